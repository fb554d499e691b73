//! One reply line for every input line.
//!
//! A [`Session`] runs bytes through the [`Framer`], parses each line,
//! hands each command to a [`Handler`] and writes exactly one reply line
//! for every line, whatever the line was: `ok …` or `err <code> <reason>`,
//! ending in CR LF. Lines that are not commands are answered by the
//! session itself; the handler only hears about them
//! ([`Handler::rejected`]).
//!
//! **Machine mode.** A line that starts with `#` carries a sequence number
//! and a checksum, for programs that want to match replies to commands and
//! catch damaged lines:
//!
//! ```text
//! #<seq> <command> *<crc>      →      #<seq> ok … *<crc>
//! ```
//!
//! `<seq>` is a decimal `u32`, echoed in the reply; `<crc>` is the CRC-8
//! (`SMBus`: polynomial 0x07, initial value 0, no reflection; "123456789"
//! gives `f4`) of every byte before the ` *`, as two hex digits (either
//! case in a command, lower case in a reply). A line with a bad sequence
//! number or checksum is not carried out and gets `err line …`.

use crate::text::{Describe, Text, display_from_describe, hex_digit};

use crc::{CRC_8_SMBUS, Crc, Table};

use super::framer::{Framer, LineError};
use super::reply::{ErrorCode, Reply, TAIL};
use super::{ParseError, parse};
use crate::command::Command;

/// The machine-mode checksum, from a 256-byte table in flash: a byte costs
/// a few instructions, where bit by bit it cost over forty.
static CRC8: Crc<u8, Table<1>> = Crc::<u8, Table<1>>::new(&CRC_8_SMBUS);

/// The CRC-8 of `bytes` as machine mode computes it.
///
/// ```
/// assert_eq!(idle_head_core::console::checksum(b"123456789"), 0xf4);
/// ```
#[must_use]
pub fn checksum(bytes: &[u8]) -> u8 {
    CRC8.checksum(bytes)
}

/// What is wrong with a machine-mode line's envelope.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EnvelopeError {
    /// `#` is not followed by a decimal `u32` and a blank.
    BadSequence,
    /// The line does not end in ` *` and two hex digits.
    MissingChecksum,
    /// The checksum does not match the line.
    BadChecksum {
        /// What the line says.
        found: u8,
        /// What the line's bytes give.
        computed: u8,
    },
}

impl Describe for EnvelopeError {
    fn describe(&self, out: &mut dyn Text) {
        match *self {
            Self::BadSequence => out.str("bad sequence number (`#<seq> <command> *<crc>`)"),
            Self::MissingChecksum => out.str("missing checksum (end the line with ` *<crc>`)"),
            Self::BadChecksum { found, computed } => out
                .str("checksum ")
                .hex2(found)
                .str(" does not match the line (")
                .hex2(computed)
                .str(")"),
        };
    }
}

display_from_describe!(EnvelopeError);

/// Why a line was not a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InputError {
    /// The framer's verdict: too long, a control byte, not UTF-8.
    Line(LineError),
    /// A machine-mode line with a bad sequence number or checksum.
    Envelope(EnvelopeError),
    /// Not a command.
    Parse(ParseError),
}

impl InputError {
    /// The reply's error code.
    #[must_use]
    pub const fn code(&self) -> ErrorCode {
        match self {
            Self::Line(_) | Self::Envelope(_) => ErrorCode::Line,
            Self::Parse(e) => ErrorCode::of(e),
        }
    }
}

/// What carries out the commands: the firmware's command queue, a
/// simulated head in a test.
pub trait Handler {
    /// Carries out `command` and writes its reply: [`Reply::ok`] with any
    /// details, or [`Reply::err`] with a reason. A reply left alone is a
    /// bare `ok`.
    fn command(&mut self, command: Command, reply: &mut Reply<'_>);

    /// A line that was not a command; the session has written its `err`
    /// reply. Does nothing unless overridden (e.g. to count errors).
    fn rejected(&mut self, error: &InputError) {
        let _ = error;
    }
}

/// A closure is a handler that hears only about commands.
impl<F: FnMut(Command, &mut Reply<'_>)> Handler for F {
    fn command(&mut self, command: Command, reply: &mut Reply<'_>) {
        self(command, reply);
    }
}

/// The smallest reply buffer a [`Session`] accepts: room for the longest
/// machine-mode prefix and error code with the line's end.
pub const MIN_REPLY: usize = 48;

/// Bytes of a line on a port, as `docs/user/protocol.md` promises (and
/// the Bottango modules answer reports, [`crate::bottango::MAX_LINE`]).
pub const PORT_LINE: usize = 96;

/// Bytes of a reply line on a port, as `docs/user/protocol.md` promises:
/// the longest `status` (every field at its widest) fits.
pub const PORT_REPLY: usize = 256;

/// A console session on a port: the sizes the protocol promises.
pub type PortSession = Session<PORT_LINE, PORT_REPLY>;

/// A console session: a line framer of `LINE` bytes and a reply buffer of
/// `REPLY` bytes (at least [`MIN_REPLY`]), no allocation.
///
/// ```
/// use core::fmt::Write;
/// use idle_head_core::command::Command;
/// use idle_head_core::console::{Reply, Session};
///
/// let mut session = Session::<96, 128>::new();
/// let mut handler = |command: Command, reply: &mut Reply<'_>| {
///     if command == Command::Status {
///         write!(reply.ok(), "mode=idle").ok();
///     }
/// };
/// let mut replies = Vec::new();
/// session.feed(b"status\r\nstop\nnodd\r\n", &mut handler, |reply| replies.push(reply.to_vec()));
/// assert_eq!(replies, [
///     b"ok mode=idle\r\n".to_vec(),
///     b"ok\r\n".to_vec(),
///     b"err syntax unknown command `nodd` (try `help`)\r\n".to_vec(),
/// ]);
/// ```
#[derive(Clone, Debug)]
pub struct Session<const LINE: usize = PORT_LINE, const REPLY: usize = PORT_REPLY> {
    framer: Framer<LINE>,
    reply: [u8; REPLY],
    /// The reply that waits for the frame task, in `reply`.
    later: Option<Later>,
}

impl<const LINE: usize, const REPLY: usize> Default for Session<LINE, REPLY> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const LINE: usize, const REPLY: usize> Session<LINE, REPLY> {
    /// A session with no line in progress.
    #[must_use]
    pub const fn new() -> Self {
        const { assert!(REPLY >= MIN_REPLY, "the reply buffer is too small") };
        Self {
            framer: Framer::new(),
            reply: [0; REPLY],
            later: None,
        }
    }

    /// Takes one byte; at a line end, the reply line (CR LF included), or
    /// nothing if the reply waits for the frame task ([`waiting`](Self::waiting)).
    ///
    /// While a reply waits, finish it ([`finish`](Self::finish)) before
    /// pushing more: a byte pushed meanwhile is not taken (`None`), as
    /// the line it belongs to could not be answered in order.
    pub fn push<H: Handler + ?Sized>(&mut self, byte: u8, handler: &mut H) -> Option<&[u8]> {
        self.step(byte)?.answer(handler)
    }

    /// Takes one byte as [`push`](Self::push) does; at a line end, the
    /// line with the reply buffer, for the caller to answer it
    /// ([`Ended::answer`] as `push` does, or as it likes).
    pub(super) fn step(&mut self, byte: u8) -> Option<Ended<'_>> {
        if self.later.is_some() {
            return None;
        }
        let line = self.framer.push(byte)?;
        Some(Ended {
            line,
            reply: &mut self.reply,
            later: &mut self.later,
        })
    }

    /// The ticket of the action whose outcome the last line's reply waits
    /// for, if it waits (see [`Reply::defer`]).
    #[must_use]
    pub fn waiting(&self) -> Option<u8> {
        self.later.map(|later| later.ticket())
    }

    /// Finishes the reply that waits, `write` writing its verdict (with
    /// [`super::answer`] from the outcome, or [`super::unanswered`]), and
    /// returns it; `None` if no reply waits.
    pub fn finish(&mut self, write: impl FnOnce(&mut Reply<'_>)) -> Option<&[u8]> {
        let later = self.later.take()?;
        Some(later.finish(&mut self.reply, write))
    }

    /// Takes the reply that waits, if one does, for the caller to write
    /// once the outcome is there ([`Later::finish`]): the session takes the
    /// next bytes meanwhile, so that the lines after it are read (and
    /// answered, in order, by the caller) while it waits.
    pub fn take_later(&mut self) -> Option<Later> {
        self.later.take()
    }

    /// Takes a run of bytes, calling `emit` with each reply line. For
    /// handlers that answer at once: this cannot wait for the frame task,
    /// so a reply that would wait is finished at once as
    /// [`unanswered`](super::unanswered).
    pub fn feed<H: Handler + ?Sized>(
        &mut self,
        bytes: &[u8],
        handler: &mut H,
        mut emit: impl FnMut(&[u8]),
    ) {
        for &byte in bytes {
            if let Some(reply) = self.push(byte, handler) {
                emit(reply);
            }
            if let Some(reply) = self.finish(|reply| super::unanswered(reply, 0)) {
                emit(reply);
            }
        }
    }

    /// The reply buffer, for a line of the console's own between replies
    /// (a telemetry line); it holds a reply that waits, if one does, so
    /// then the buffer is not handed out (an empty one is).
    pub(super) fn spare(&mut self) -> &mut [u8] {
        if self.later.is_some() {
            return &mut [];
        }
        &mut self.reply
    }

    /// Whether a line has begun and not ended.
    pub(super) const fn in_progress(&self) -> bool {
        self.framer.in_progress()
    }

    /// Drops the line in progress, unanswered, and hands out the reply
    /// buffer for what the caller answers instead (a Bottango `TIMEOUT`).
    pub(super) fn drop_line(&mut self) -> &mut [u8] {
        self.framer.reset();
        &mut self.reply
    }

    /// Forgets the line in progress and a reply that waits (e.g. when the
    /// port reconnects: the new host did not send that line).
    pub fn reset(&mut self) {
        self.framer.reset();
        self.later = None;
    }

    /// Notes that the port lost received bytes (see [`Framer::lose`]):
    /// the line they belonged to is answered `err line bytes lost …`.
    pub fn lose(&mut self) {
        self.framer.lose();
    }
}

/// A line a [`Session`] framed, and where its reply goes.
pub(super) struct Ended<'s> {
    /// The framer's outcome.
    pub(super) line: Result<&'s [u8], LineError>,
    /// The session's reply buffer.
    pub(super) reply: &'s mut [u8],
    later: &'s mut Option<Later>,
}

impl<'s> Ended<'s> {
    /// The console's reply ([`respond`]): the line, or nothing if it
    /// waits for the frame task (the session then keeps it).
    pub(super) fn answer<H: Handler + ?Sized>(self, handler: &mut H) -> Option<&'s [u8]> {
        match respond(self.line, handler, self.reply) {
            Response::Now(line) => Some(line),
            Response::Later(later) => {
                *self.later = Some(later);
                None
            }
        }
    }
}

/// A reply: the line, or a reply that waits for the frame task.
#[derive(Debug, PartialEq, Eq)]
pub enum Response<'b> {
    /// The reply line (CR LF included).
    Now(&'b [u8]),
    /// The handler deferred the reply ([`Reply::defer`]): finish it with
    /// [`Later::finish`] in the same buffer once the outcome is there.
    Later(Later),
}

impl<'b> Response<'b> {
    /// The line, if the reply did not wait.
    #[must_use]
    pub fn now(self) -> Option<&'b [u8]> {
        match self {
            Self::Now(line) => Some(line),
            Self::Later(_) => None,
        }
    }
}

/// A reply that waits for the outcome of a queued action: all it needs to
/// be written later, in any buffer (a machine-mode sequence number
/// included).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Later {
    ticket: u8,
    /// The machine-mode sequence number, for a machine-mode line.
    seq: Option<u32>,
    machine: bool,
}

impl Later {
    /// The ticket of the action whose outcome the reply waits for.
    #[must_use]
    pub const fn ticket(&self) -> u8 {
        self.ticket
    }

    /// Writes the reply into `out`, `write` writing its verdict (a reply
    /// left alone, or deferred again, is a bare `ok`).
    pub fn finish(self, out: &mut [u8], write: impl FnOnce(&mut Reply<'_>)) -> &[u8] {
        let mut reply = Reply::new(out);
        if let Some(seq) = self.seq {
            reply.prefix(seq);
        }
        write(&mut reply);
        if self.machine {
            sign(reply)
        } else {
            reply.finish()
        }
    }
}

/// The reply to one line outcome of a [`Framer`], written into `out`
/// (at least [`MIN_REPLY`] bytes, or replies are cut short): what a
/// [`Session`] does for each line.
pub fn respond<'b, H: Handler + ?Sized>(
    line: Result<&[u8], LineError>,
    handler: &mut H,
    out: &'b mut [u8],
) -> Response<'b> {
    let mut reply = Reply::new(out);
    let machine = matches!(line, Ok(text) if text.first() == Some(&b'#'));
    let mut seq = None;
    match line {
        Ok(text) if machine => {
            let envelope = envelope(text);
            seq = envelope.seq;
            if let Some(seq) = seq {
                reply.prefix(seq);
            }
            match envelope.command {
                Ok(command) => answer(command, handler, &mut reply),
                Err(error) => reject(InputError::Envelope(error), &[], handler, &mut reply),
            }
        }
        Ok(text) => answer(text, handler, &mut reply),
        Err(error) => reject(InputError::Line(error), &[], handler, &mut reply),
    }
    if let Some(ticket) = reply.later() {
        return Response::Later(Later {
            ticket,
            seq,
            machine,
        });
    }
    Response::Now(if machine { sign(reply) } else { reply.finish() })
}

/// Closes a machine-mode reply: its checksum and the line end.
fn sign(mut reply: Reply<'_>) -> &[u8] {
    reply.close();
    let crc = checksum(reply.text());
    reply.append_tail(&[b' ', b'*', hex_digit(crc >> 4), hex_digit(crc)]);
    reply.end_line();
    reply.into_line()
}

// The tail kept by every reply holds the checksum and the line end.
const _: () = assert!(TAIL >= "…".len() + " *hh".len() + "\r\n".len());

/// Parses `line` and carries it out, or rejects it.
fn answer<H: Handler + ?Sized>(line: &[u8], handler: &mut H, reply: &mut Reply<'_>) {
    match parse(line) {
        Ok(command) => handler.command(command, reply),
        Err(error) => reject(InputError::Parse(error), line, handler, reply),
    }
}

/// Writes the `err` reply for `error` (`line`: the parsed line, for the
/// quoted word of a parse error).
fn reject<H: Handler + ?Sized>(
    error: InputError,
    line: &[u8],
    handler: &mut H,
    reply: &mut Reply<'_>,
) {
    let text: &mut dyn Text = reply.err(error.code());
    match &error {
        InputError::Line(e) => text.with(e),
        InputError::Envelope(e) => text.with(e),
        InputError::Parse(e) => text.with(&e.describing(line)),
    };
    handler.rejected(&error);
}

/// A machine-mode line taken apart: the sequence number if it could be
/// read, and the command if the envelope is sound.
struct Envelope<'a> {
    seq: Option<u32>,
    command: Result<&'a [u8], EnvelopeError>,
}

/// Splits `#<seq> <command> *<hh>`, checking the checksum.
fn envelope(line: &[u8]) -> Envelope<'_> {
    let rest = line.get(1..).unwrap_or_default();
    let digits = rest.iter().take_while(|b| b.is_ascii_digit()).count();
    let after = rest.get(digits..).unwrap_or_default();
    let (Some(seq), [] | [b' ' | b'\t', ..]) =
        (decimal_u32(rest.get(..digits).unwrap_or_default()), after)
    else {
        return Envelope {
            seq: None,
            command: Err(EnvelopeError::BadSequence),
        };
    };
    Envelope {
        seq: Some(seq),
        command: checked_command(line, digits),
    }
}

/// The command of a machine-mode line whose sequence number has `digits`
/// digits, if the line ends in its checksum.
fn checked_command(line: &[u8], digits: usize) -> Result<&[u8], EnvelopeError> {
    let body_len = line
        .len()
        .checked_sub(4)
        .ok_or(EnvelopeError::MissingChecksum)?;
    let (body, tail) = line.split_at_checked(body_len).unwrap_or_default();
    let [b' ', b'*', hi, lo] = *tail else {
        return Err(EnvelopeError::MissingChecksum);
    };
    let (Some(hi), Some(lo)) = (hex_value(hi), hex_value(lo)) else {
        return Err(EnvelopeError::MissingChecksum);
    };
    let found = hi << 4 | lo;
    let computed = checksum(body);
    if computed != found {
        return Err(EnvelopeError::BadChecksum { found, computed });
    }
    // The sequence number ends before the ` *`, which is no digit.
    Ok(body.get(1 + digits..).unwrap_or_default())
}

/// 1 to 10 decimal digits that fit a `u32`.
fn decimal_u32(digits: &[u8]) -> Option<u32> {
    if digits.is_empty() || digits.len() > 10 {
        return None;
    }
    digits.iter().try_fold(0_u32, |value, &d| {
        // (Not `checked_mul`: a Cortex-M0+ widens that to 64 bits.)
        if value > u32::MAX / 10 {
            return None;
        }
        (value * 10).checked_add(u32::from(d.wrapping_sub(b'0')))
    })
}

fn hex_value(b: u8) -> Option<u8> {
    match b {
        b'0'..=b'9' => Some(b - b'0'),
        b'a'..=b'f' => Some(b - b'a' + 10),
        b'A'..=b'F' => Some(b - b'A' + 10),
        _ => None,
    }
}
