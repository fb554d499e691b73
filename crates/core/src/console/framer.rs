//! Bytes → lines: the line discipline of the console.
//!
//! A line ends at CR, LF or CR LF; backspace and DEL edit the line in
//! progress; a completed line is checked for control bytes and UTF-8. A
//! line longer than the buffer is discarded and reported once
//! ([`LineError::TooLong`]). Every line end yields exactly one outcome
//! ([`Framer::push`]).
//!
//! ```
//! use idle_head_core::console::{Framer, LineError};
//!
//! let mut framer = Framer::<16>::new();
//! let mut lines = Vec::new();
//! framer.feed(b"nod\r\nstat\x7ftus\rseed \x00\nthis line is far too long\n", |line| {
//!     lines.push(line.map(|bytes| bytes.to_vec()));
//! });
//! assert_eq!(lines, [
//!     Ok(b"nod".to_vec()),
//!     Ok(b"status".to_vec()),
//!     Err(LineError::Control { at: 5, byte: 0 }),
//!     Err(LineError::TooLong { len: 25, max: 16 }),
//! ]);
//! ```
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The line discipline”).

use crate::text::{Describe, Text, display_from_describe};

/// What is wrong with a line (the framer's part: the parser judges the rest).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LineError {
    /// The line did not fit the buffer: `len` bytes arrived for it (line
    /// end not counted, edits after the overflow counted), at most `max`
    /// are allowed.
    TooLong {
        /// Bytes received for the line.
        len: usize,
        /// The buffer's capacity.
        max: usize,
    },
    /// A control byte (NUL, ESC, ...) at byte `at` of the edited line.
    Control {
        /// Its position.
        at: usize,
        /// The byte.
        byte: u8,
    },
    /// Not UTF-8 from byte `at` on.
    NotUtf8 {
        /// Where the first invalid sequence starts.
        at: usize,
    },
    /// Bytes of the line were lost on the way in (the port reported a
    /// receive error, such as a UART overrun: see [`Framer::lose`]).
    Lost,
}

impl Describe for LineError {
    fn describe(&self, out: &mut dyn Text) {
        match *self {
            Self::TooLong { len, max } => out
                .str("too long (")
                .u64(len as u64)
                .str(" bytes, at most ")
                .u64(max as u64)
                .str(")"),
            Self::Control { at, byte } => out
                .str("control byte 0x")
                .hex2(byte)
                .str(" at byte ")
                .u64(at as u64),
            Self::NotUtf8 { at } => out.str("not UTF-8 from byte ").u64(at as u64).str(" on"),
            Self::Lost => out.str("bytes lost on the way in (a receive error): send it again"),
        };
    }
}

display_from_describe!(LineError);

/// Backspace.
const BS: u8 = 0x08;
/// DEL, what most terminals send for the backspace key.
const DEL: u8 = 0x7f;
const CR: u8 = b'\r';
const LF: u8 = b'\n';

/// The line framer: a fixed buffer of `N` bytes, no allocation.
#[derive(Clone, Debug)]
pub struct Framer<const N: usize> {
    buf: [u8; N],
    /// Bytes of the line so far (after edits), at most `N`.
    len: usize,
    /// Bytes that did not fit; nonzero marks the line as too long.
    dropped: usize,
    /// Bytes of the line were lost before they reached the framer.
    lost: bool,
    /// The last byte was a CR: an LF now belongs to the same line end.
    after_cr: bool,
    /// The last call completed a line: start a new one.
    done: bool,
}

impl<const N: usize> Default for Framer<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Framer<N> {
    /// The longest line, in bytes.
    pub const CAPACITY: usize = N;

    /// An empty framer.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            buf: [0; N],
            len: 0,
            dropped: 0,
            lost: false,
            after_cr: false,
            done: false,
        }
    }

    /// Takes one byte; at a line end, the line's outcome. The returned
    /// bytes are the line without its end.
    ///
    /// # Errors
    /// A [`LineError`] for a line that is too long, holds a control byte
    /// or is not UTF-8.
    pub fn push(&mut self, byte: u8) -> Option<Result<&[u8], LineError>> {
        if self.done {
            self.start_line();
        }
        let after_cr = core::mem::replace(&mut self.after_cr, byte == CR);
        match byte {
            LF if after_cr => None,
            CR | LF => {
                self.done = true;
                Some(self.finish())
            }
            BS | DEL => {
                if self.dropped > 0 {
                    // The line is lost already; count what arrived for it.
                    self.dropped = self.dropped.saturating_add(1);
                } else {
                    self.len = self.char_start();
                }
                None
            }
            _ => {
                if self.dropped > 0 {
                    self.dropped = self.dropped.saturating_add(1);
                } else if let Some(slot) = self.buf.get_mut(self.len) {
                    *slot = byte;
                    self.len += 1;
                } else {
                    self.dropped = 1;
                }
                None
            }
        }
    }

    /// Takes a run of bytes, calling `line` with each completed line's
    /// outcome (see [`push`](Self::push)).
    pub fn feed(&mut self, bytes: &[u8], mut line: impl FnMut(Result<&[u8], LineError>)) {
        for &byte in bytes {
            if let Some(outcome) = self.push(byte) {
                line(outcome);
            }
        }
    }

    /// Whether bytes of a line have arrived and its end has not yet.
    #[must_use]
    pub const fn in_progress(&self) -> bool {
        !self.done && (self.len > 0 || self.dropped > 0 || self.lost)
    }

    /// Forgets the line in progress (e.g. when the port reconnects).
    pub fn reset(&mut self) {
        *self = Self::new();
    }

    /// Notes that bytes were lost before they reached the framer (a UART
    /// overrun, a framing error): the line they belonged to, the one in
    /// progress or, after a line end, the next, ends in
    /// [`LineError::Lost`]. Its line end may have been lost too, so that
    /// line can run into the next: both then get the one reply. A lost
    /// CR also loses the pairing of a following LF with it.
    pub fn lose(&mut self) {
        if self.done {
            self.start_line();
        }
        self.lost = true;
        self.after_cr = false;
    }

    /// Starts a new line.
    fn start_line(&mut self) {
        self.done = false;
        self.len = 0;
        self.dropped = 0;
        self.lost = false;
    }

    /// Where the last character of the line starts: a backspace deletes
    /// a whole UTF-8 sequence, or a single byte that starts none.
    fn char_start(&self) -> usize {
        let line = self.buf.get(..self.len).unwrap_or_default();
        let Some(last) = self.len.checked_sub(1) else {
            return 0;
        };
        // The lead byte is at most 3 bytes before the last one.
        let lead = line
            .iter()
            .enumerate()
            .skip(self.len.saturating_sub(4))
            .rev()
            .find(|&(_, &b)| !is_continuation(b));
        match lead {
            Some((at, &b)) if self.len - at <= sequence_len(b) => at,
            _ => last,
        }
    }

    /// The outcome of the completed line.
    fn finish(&self) -> Result<&[u8], LineError> {
        if self.lost {
            return Err(LineError::Lost);
        }
        if self.dropped > 0 {
            return Err(LineError::TooLong {
                len: N.saturating_add(self.dropped),
                max: N,
            });
        }
        let line = self.buf.get(..self.len).unwrap_or_default();
        if let Some((at, &byte)) = line
            .iter()
            .enumerate()
            .find(|&(_, &b)| b < 0x20 && b != b'\t')
        {
            return Err(LineError::Control { at, byte });
        }
        match core::str::from_utf8(line) {
            Ok(_) => Ok(line),
            Err(e) => Err(LineError::NotUtf8 {
                at: e.valid_up_to(),
            }),
        }
    }
}

/// A UTF-8 continuation byte (`10xxxxxx`).
const fn is_continuation(b: u8) -> bool {
    b & 0xc0 == 0x80
}

/// Bytes in the UTF-8 sequence that `lead` starts (1 for ASCII and for
/// bytes that start none).
const fn sequence_len(lead: u8) -> usize {
    match lead {
        0xc0..=0xdf => 2,
        0xe0..=0xef => 3,
        0xf0..=0xf7 => 4,
        _ => 1,
    }
}
