//! Reply lines: `ok …` or `err <code> <reason>`, formatted into a fixed
//! buffer.
//!
//! A reply is always one line: characters that could break it (CR, LF and
//! every other control character) are written as `?`, and text that does
//! not fit is cut at a character boundary and marked with `…` (the only
//! non-ASCII character a reply can contain: the parser quotes other bytes
//! as `\xNN`). Text and numbers go in through [`Text`], not `core::fmt`
//! (see [`crate::text`]); nothing here formats a float, which would link
//! about 30 KB of float formatting.

use core::fmt;

use crate::text::{Describe, Text, display_from_describe};

use super::ParseError;

/// The error codes of the protocol, the word after `err`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ErrorCode {
    /// `syntax`: the line is not a command (unknown word, missing or extra
    /// argument, not a number).
    Syntax,
    /// `range`: a number outside what its field can hold.
    Range,
    /// `line`: the line itself is unusable (too long, a control byte, not
    /// UTF-8, a bad sequence number or checksum in machine mode).
    Line,
    /// `busy`: the command queue is full; nothing was done, send it again.
    Busy,
    /// `invalid`: a setting that fails validation (as the typed
    /// configuration would).
    Invalid,
    /// `limit`: a target past a servo's limits.
    Limit,
    /// `storage`: reading or writing the settings in flash failed.
    Storage,
    /// `state`: the command makes no sense now (e.g. a gesture while the
    /// head is stopped).
    State,
    /// `unavailable`: the board lacks the part the command needs (no
    /// settings store, DMX receiver, radar, or no such input).
    Unavailable,
}

impl ErrorCode {
    /// Every code, in the order of the documentation.
    pub const ALL: [Self; 9] = [
        Self::Syntax,
        Self::Range,
        Self::Line,
        Self::Busy,
        Self::Invalid,
        Self::Limit,
        Self::Storage,
        Self::State,
        Self::Unavailable,
    ];

    /// The word on the wire.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Syntax => "syntax",
            Self::Range => "range",
            Self::Line => "line",
            Self::Busy => "busy",
            Self::Invalid => "invalid",
            Self::Limit => "limit",
            Self::Storage => "storage",
            Self::State => "state",
            Self::Unavailable => "unavailable",
        }
    }

    /// The code of a parse error (`range` for a number out of range,
    /// `syntax` otherwise; the same word as [`ParseError::code`]).
    #[must_use]
    pub const fn of(error: &ParseError) -> Self {
        match error.kind {
            super::ParseErrorKind::OutOfRange { .. } => Self::Range,
            _ => Self::Syntax,
        }
    }
}

impl Describe for ErrorCode {
    fn describe(&self, out: &mut dyn Text) {
        out.str(self.as_str());
    }
}

display_from_describe!(ErrorCode);

/// What a reply says so far.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Verdict {
    /// Nothing yet: the reply is a bare `ok`.
    Unset,
    Ok,
    Err,
    /// The reply waits for the outcome of the action with this ticket.
    Later(u8),
}

/// Bytes kept free at the end of the buffer: `…` (3), a machine-mode
/// checksum ` *hh` (4) and CR LF (2).
pub(super) const TAIL: usize = 9;

/// The truncation mark.
const ELLIPSIS: &str = "…";

/// One reply line being written into a fixed buffer.
///
/// [`ok`](Self::ok) or [`err`](Self::err) starts it (a reply nobody
/// started is a bare `ok`), then text follows through [`Text`] (the
/// firmware's way, without `core::fmt`) or [`fmt::Write`] (`write!`, the
/// same text): the first piece of text is separated from the verdict by a
/// space. Writing never fails; text that does not fit is dropped and the
/// reply ends in `…`.
///
/// ```
/// use core::fmt::Write;
/// use idle_head_core::console::{ErrorCode, Reply};
/// use idle_head_core::text::{Arg, Text};
///
/// let mut buf = [0; 64];
/// let mut reply = Reply::new(&mut buf);
/// let text: &mut dyn Text = reply.err(ErrorCode::Limit);
/// text.fill("pitch {} mdeg is past {}", &[Arg::Int(31_000), Arg::Int(20_000)]);
/// assert_eq!(reply.finish(), b"err limit pitch 31000 mdeg is past 20000\r\n");
///
/// // Too long for the buffer: cut, and marked.
/// let mut buf = [0; 36];
/// let mut reply = Reply::new(&mut buf);
/// write!(reply.ok(), "pitch={} roll={}\nyaw={}", -1234, 5678, 0).ok();
/// assert_eq!(reply.finish(), "ok pitch=-1234 roll=5678?ya…\r\n".as_bytes());
/// ```
#[derive(Debug)]
pub struct Reply<'a> {
    buf: &'a mut [u8],
    /// Where the verdict starts (after a machine-mode sequence number).
    start: usize,
    len: usize,
    /// The text may not go past this.
    limit: usize,
    verdict: Verdict,
    /// The next text needs a space before it.
    space: bool,
    truncated: bool,
}

impl<'a> Reply<'a> {
    /// A reply written into `buf`; its last 9 bytes are kept for the end
    /// of the line (`…`, a machine-mode checksum, CR LF).
    #[must_use]
    pub fn new(buf: &'a mut [u8]) -> Self {
        let limit = buf.len().saturating_sub(TAIL);
        Self {
            buf,
            start: 0,
            len: 0,
            limit,
            verdict: Verdict::Unset,
            space: false,
            truncated: false,
        }
    }

    /// Writes `#<seq> ` (a machine-mode sequence number) before the verdict.
    pub(super) fn prefix(&mut self, seq: u32) {
        self.len = 0;
        self.space = false;
        let raw: &mut dyn Text = self;
        raw.str("#").u64(seq.into()).str(" ");
        self.start = self.len;
        self.verdict = Verdict::Unset;
    }

    /// Defers the reply until the action with `ticket` has been taken or
    /// refused by the frame task (see [`Session::waiting`]); text written
    /// so far is dropped.
    ///
    /// [`Session::waiting`]: super::Session::waiting
    pub fn defer(&mut self, ticket: u8) {
        self.len = self.start;
        self.truncated = false;
        self.space = false;
        self.verdict = Verdict::Later(ticket);
    }

    /// The ticket of the outcome the reply waits for, if deferred.
    #[must_use]
    pub fn later(&self) -> Option<u8> {
        match self.verdict {
            Verdict::Later(ticket) => Some(ticket),
            _ => None,
        }
    }

    /// Starts (or restarts) the reply as `ok`; text written next follows it.
    pub fn ok(&mut self) -> &mut Self {
        self.restart(Verdict::Ok, "ok", "")
    }

    /// Starts (or restarts) the reply as `err <code>`; text written next is
    /// the reason.
    pub fn err(&mut self, code: ErrorCode) -> &mut Self {
        self.restart(Verdict::Err, "err ", code.as_str())
    }

    /// Whether the reply is an error so far.
    #[must_use]
    pub fn is_err(&self) -> bool {
        self.verdict == Verdict::Err
    }

    fn restart(&mut self, verdict: Verdict, head: &str, code: &str) -> &mut Self {
        self.len = self.start;
        self.truncated = false;
        self.space = false;
        self.put_str(head);
        self.put_str(code);
        self.verdict = verdict;
        self.space = true;
        self
    }

    /// The line so far, without its end.
    pub(super) fn text(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or_default()
    }

    /// Appends raw ASCII (`…`, a checksum, the line end) into the kept tail.
    pub(super) fn append_tail(&mut self, bytes: &[u8]) {
        let end = self.len.saturating_add(bytes.len());
        if let Some(dst) = self.buf.get_mut(self.len..end) {
            for (d, &s) in dst.iter_mut().zip(bytes) {
                *d = s;
            }
            self.len = end;
        }
    }

    /// Closes the line: a bare `ok` if nothing was written, the truncation
    /// mark if needed, CR LF. Returns the whole line.
    #[must_use]
    pub fn finish(mut self) -> &'a [u8] {
        self.close();
        self.end_line();
        let Self { buf, len, .. } = self;
        buf.get(..len).unwrap_or_default()
    }

    /// Everything but the line end (machine mode adds its checksum after).
    pub(super) fn close(&mut self) {
        if matches!(self.verdict, Verdict::Unset | Verdict::Later(_)) {
            self.ok();
        }
        if self.truncated {
            self.truncated = false;
            self.append_tail(ELLIPSIS.as_bytes());
        }
    }

    pub(super) fn end_line(&mut self) {
        self.append_tail(b"\r\n");
    }

    /// Consumes the reply, returning the line written so far.
    pub(super) fn into_line(self) -> &'a [u8] {
        let Self { buf, len, .. } = self;
        buf.get(..len).unwrap_or_default()
    }

    /// Appends one byte if it fits before the limit.
    fn put_byte(&mut self, byte: u8) -> bool {
        if self.len >= self.limit {
            return false;
        }
        let Some(dst) = self.buf.get_mut(self.len) else {
            return false;
        };
        *dst = byte;
        self.len += 1;
        true
    }

    /// Appends one character if it fits before the limit.
    fn put_char(&mut self, c: char) -> bool {
        let mut utf8 = [0; 4];
        let bytes = c.encode_utf8(&mut utf8).as_bytes();
        let end = self.len.saturating_add(bytes.len());
        if end > self.limit {
            return false;
        }
        let Some(dst) = self.buf.get_mut(self.len..end) else {
            return false;
        };
        for (d, &s) in dst.iter_mut().zip(bytes) {
            *d = s;
        }
        self.len = end;
        true
    }
}

impl Reply<'_> {
    /// Appends `s` (after the separating space, if one is due), control
    /// characters as `?`, up to the limit.
    fn put_str(&mut self, s: &str) {
        if self.truncated || s.is_empty() {
            return;
        }
        if core::mem::take(&mut self.space) && !self.put_char(' ') {
            self.truncated = true;
            return;
        }
        for c in s.chars() {
            // ASCII, almost every character, a byte at a time.
            let fits = if c.is_ascii() {
                self.put_byte(if c.is_ascii_control() { b'?' } else { c as u8 })
            } else {
                self.put_char(if c.is_control() { '?' } else { c })
            };
            if !fits {
                self.truncated = true;
                break;
            }
        }
    }
}

impl Text for Reply<'_> {
    fn put(&mut self, s: &str) {
        self.put_str(s);
    }
}

/// `write!` works too (on the host, in tests): the same text as [`Text`].
impl fmt::Write for Reply<'_> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.put_str(s);
        Ok(())
    }
}
