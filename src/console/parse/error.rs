//! What went wrong in a line, where, and how it reads.

use core::fmt;

/// Where in the line an error is: a byte range (empty at the end of the line).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Span {
    /// First byte.
    pub start: u16,
    /// One past the last byte.
    pub end: u16,
}

/// What is wrong with a line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ParseErrorKind {
    /// Nothing but spaces.
    Empty,
    /// The first word is not a command.
    UnknownCommand,
    /// The line ends where this was expected.
    Missing(&'static str),
    /// A word too many.
    Unexpected,
    /// Not a whole number (this was expected).
    NotANumber(&'static str),
    /// A number outside what its field can hold.
    OutOfRange {
        /// The field.
        what: &'static str,
        /// Smallest allowed.
        min: i64,
        /// Largest allowed.
        max: i64,
    },
    /// Not one of the words allowed here.
    UnknownWord {
        /// The words allowed here.
        expected: &'static str,
    },
    /// A `name=value` option this command does not have.
    UnknownOption {
        /// The options it has.
        allowed: &'static str,
    },
    /// The same option twice.
    DuplicateOption,
}

/// A rejected line: what is wrong and where.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParseError {
    /// What is wrong.
    pub kind: ParseErrorKind,
    /// The offending word.
    pub at: Span,
}

impl ParseError {
    /// The reply code: `range` for a number out of range, `syntax` otherwise.
    #[must_use]
    pub const fn code(&self) -> &'static str {
        match self.kind {
            ParseErrorKind::OutOfRange { .. } => "range",
            _ => "syntax",
        }
    }

    /// A one-line reason, quoting the offending word of `line` (the line
    /// that was parsed).
    #[must_use]
    pub fn describe<'a>(&'a self, line: &'a [u8]) -> impl fmt::Display + 'a {
        Describe { error: self, line }
    }
}

struct Describe<'a> {
    error: &'a ParseError,
    line: &'a [u8],
}

impl fmt::Display for Describe<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Span { start, end } = self.error.at;
        let word = self
            .line
            .get(usize::from(start)..usize::from(end))
            .unwrap_or_default();
        let quoted = Quoted(word);
        match self.error.kind {
            ParseErrorKind::Empty => f.write_str("empty line (try `help`)"),
            ParseErrorKind::UnknownCommand => write!(f, "unknown command {quoted} (try `help`)"),
            ParseErrorKind::Missing(what) => write!(f, "missing {what}"),
            ParseErrorKind::Unexpected => write!(f, "{quoted}: unexpected"),
            ParseErrorKind::NotANumber(what) => {
                write!(f, "{quoted}: {what} must be a whole number")
            }
            ParseErrorKind::OutOfRange { what, min, max } => {
                write!(f, "{quoted}: {what} must be in {min}..={max}")
            }
            ParseErrorKind::UnknownWord { expected } => write!(f, "{quoted}: expected {expected}"),
            ParseErrorKind::UnknownOption { allowed } => {
                write!(f, "{quoted}: unknown option (allowed: {allowed})")
            }
            ParseErrorKind::DuplicateOption => write!(f, "{quoted}: option given twice"),
        }
    }
}

/// A word in backquotes, bytes that are not printable ASCII as `\xNN`.
struct Quoted<'a>(&'a [u8]);

impl fmt::Display for Quoted<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("`")?;
        for &b in self.0 {
            if b.is_ascii_graphic() {
                write!(f, "{}", char::from(b))?;
            } else {
                write!(f, "\\x{b:02x}")?;
            }
        }
        f.write_str("`")
    }
}
