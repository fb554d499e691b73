//! What went wrong in a line, where, and how it reads.

use core::fmt;

use crate::text::Arg::{Int, Str, Text};
use crate::text::{self, Text as Out};

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
        self.describing(line)
    }

    /// The same reason as a [`text::Describe`], for replies.
    pub(crate) const fn describing<'a>(&'a self, line: &'a [u8]) -> Describe<'a> {
        Describe { error: self, line }
    }
}

/// A parse error's reason with its line.
pub(crate) struct Describe<'a> {
    error: &'a ParseError,
    line: &'a [u8],
}

impl text::Describe for Describe<'_> {
    fn describe(&self, out: &mut dyn Out) {
        let Span { start, end } = self.error.at;
        let word = self
            .line
            .get(usize::from(start)..usize::from(end))
            .unwrap_or_default();
        let quoted = Quoted(word);
        match self.error.kind {
            ParseErrorKind::Empty => out.str("empty line (try `help`)"),
            ParseErrorKind::UnknownCommand => {
                out.fill("unknown command {} (try `help`)", &[Text(&quoted)])
            }
            ParseErrorKind::Missing(what) => out.str("missing ").str(what),
            ParseErrorKind::Unexpected => out.fill("{}: unexpected", &[Text(&quoted)]),
            ParseErrorKind::NotANumber(what) => {
                out.fill("{}: {} must be a whole number", &[Text(&quoted), Str(what)])
            }
            ParseErrorKind::OutOfRange { what, min, max } => out.fill(
                "{}: {} must be in {}..={}",
                &[Text(&quoted), Str(what), Int(min), Int(max)],
            ),
            ParseErrorKind::UnknownWord { expected } => {
                out.fill("{}: expected {}", &[Text(&quoted), Str(expected)])
            }
            ParseErrorKind::UnknownOption { allowed } => out.fill(
                "{}: unknown option (allowed: {})",
                &[Text(&quoted), Str(allowed)],
            ),
            ParseErrorKind::DuplicateOption => out.fill("{}: option given twice", &[Text(&quoted)]),
        };
    }
}

/// A word in backquotes, bytes that are not printable ASCII as `\xNN`.
struct Quoted<'a>(&'a [u8]);

impl text::Describe for Quoted<'_> {
    fn describe(&self, out: &mut dyn Out) {
        out.str("`");
        for b in self.0 {
            match core::str::from_utf8(core::slice::from_ref(b)) {
                Ok(c) if b.is_ascii_graphic() => out.str(c),
                _ => out.str("\\x").hex2(*b),
            };
        }
        out.str("`");
    }
}

text::display_from_describe!(Describe<'_>);
