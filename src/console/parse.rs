//! One line of the console protocol → a [`Command`].
//!
//! Words are separated by spaces or tabs and compared without regard to
//! ASCII case. Numbers are decimal integers with an optional sign, in the
//! project's units. Optional trailing options are `name=value` words, in
//! any order after the positional arguments.
//!
//! ```text
//! help | status | save | load | defaults | stop
//! nod   [amp_mdeg] [ms] [cycles=N] [intensity=PCT]
//! shake [amp_mdeg] [ms] [cycles=N] [intensity=PCT]
//! tilt  [amp_mdeg] [ms] [intensity=PCT]
//! look <pitch_mdeg> <yaw_mdeg> [ms] [hold=MS|hold=stay]
//! center [ms]
//! idle on | idle off | idle amp <percent>
//! seed <n> | seed random
//! servo <pitch|roll|yaw> [neutral <us> | per-degree <ns> | direction <normal|reversed>
//!                        | min <us> | max <us> | limits <min_mdeg> <max_mdeg>]
//! ```
//!
//! The parser checks the syntax and that each number fits its type
//! (a percentage is at most 100, a duration is positive); whether a value
//! suits the head (an amplitude inside the axis' limits, a calibration
//! that validates) is for the behaviour and the settings to decide. It
//! never panics and allocates nothing.
//!
//! ```
//! use idle_head::command::{Action, Command, GestureKind};
//! use idle_head::console::parse;
//! use idle_head::{Angle, Millis};
//!
//! let Ok(Command::Act(Action::Gesture(nod))) = parse(b"nod 6000 900 cycles=3") else {
//!     panic!("a nod")
//! };
//! assert_eq!(nod.kind, GestureKind::Nod);
//! assert_eq!(nod.amplitude, Some(Angle::from_degrees(6)));
//! assert_eq!(nod.duration, Some(Millis(900)));
//! assert_eq!(nod.cycles, Some(3));
//!
//! let err = parse(b"nod six").unwrap_err();
//! assert_eq!(err.describe(b"nod six").to_string(), "`six`: amplitude in mdeg must be a whole number");
//! ```

use core::fmt;

use crate::axis::Axis;
use crate::command::{
    Action, Command, GestureKind, GestureRequest, Hold, LookRequest, Percent, SeedChoice,
    ServoSetting,
};
use crate::servo::{Direction, NanosPerDegree};
use crate::units::{Angle, AngleRange, Microseconds, Millis};

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

/// Parses one line (without its line ending); the grammar is in this
/// module's source and, for users, in `docs/protocol.md`.
///
/// # Errors
/// A [`ParseError`] naming the first problem and the word it is in.
pub fn parse(line: &[u8]) -> Result<Command, ParseError> {
    let mut words = Words::new(line);
    let Some(first) = words.next() else {
        return Err(words.error_here(ParseErrorKind::Empty));
    };
    let command = match first.lower() {
        Word::Is("help") => Command::Help,
        Word::Is("status") => Command::Status,
        Word::Is("save") => Command::Save,
        Word::Is("load") => Command::Load,
        Word::Is("defaults") => Command::Defaults,
        Word::Is("stop") => Command::Act(Action::Stop),
        Word::Is("nod") => gesture(&mut words, GestureKind::Nod)?,
        Word::Is("shake") => gesture(&mut words, GestureKind::Shake)?,
        Word::Is("tilt") => gesture(&mut words, GestureKind::Tilt)?,
        Word::Is("look") => look(&mut words)?,
        Word::Is("center" | "centre") => Command::Act(Action::Center {
            duration: words.optional_number(DURATION)?.map(to_millis),
        }),
        Word::Is("idle") => idle(&mut words)?,
        Word::Is("seed") => seed(&mut words)?,
        Word::Is("servo") => servo(&mut words)?,
        _ => return Err(first.error(ParseErrorKind::UnknownCommand)),
    };
    words.end()?;
    Ok(command)
}

/// A numeric field: its name and range.
#[derive(Clone, Copy)]
struct Field {
    what: &'static str,
    min: i64,
    max: i64,
}

const AMPLITUDE: Field = Field {
    what: "amplitude in mdeg",
    min: i32::MIN as i64 + 1,
    max: i32::MAX as i64,
};
const ANGLE: Field = Field {
    what: "angle in mdeg",
    ..AMPLITUDE
};
const DURATION: Field = Field {
    what: "duration in ms",
    min: 1,
    max: u32::MAX as i64,
};
const HOLD: Field = Field {
    what: "hold in ms",
    min: 0,
    max: u32::MAX as i64,
};
const CYCLES: Field = Field {
    what: "cycles",
    min: 1,
    max: u8::MAX as i64,
};
const PERCENT: Field = Field {
    what: "percentage",
    min: 0,
    max: 100,
};
const SEED: Field = Field {
    what: "seed",
    min: 0,
    max: u32::MAX as i64,
};
const PULSE: Field = Field {
    what: "pulse in us",
    min: 0,
    max: u32::MAX as i64,
};
const PER_DEGREE: Field = Field {
    what: "ns per degree",
    min: 0,
    max: u32::MAX as i64,
};

fn to_angle(v: i64) -> Angle {
    Angle::from_millidegrees(v as i32)
}

fn to_millis(v: i64) -> Millis {
    Millis(v as u32)
}

fn to_percent(v: i64) -> Percent {
    Percent::new(v as u8).unwrap_or(Percent::FULL)
}

/// `nod|shake|tilt [amp] [ms] [cycles=N] [intensity=P]`.
fn gesture(words: &mut Words<'_>, kind: GestureKind) -> Result<Command, ParseError> {
    let mut request = GestureRequest::new(kind);
    request.amplitude = words.optional_number(AMPLITUDE)?.map(to_angle);
    request.duration = words.optional_number(DURATION)?.map(to_millis);
    let allowed = match kind {
        GestureKind::Tilt => "intensity",
        GestureKind::Nod | GestureKind::Shake => "cycles, intensity",
    };
    while let Some((name, value, word)) = words.option()? {
        match (name, kind) {
            ("cycles", GestureKind::Nod | GestureKind::Shake) => {
                once(request.cycles.is_some(), word)?;
                request.cycles = Some(value.number(CYCLES)? as u8);
            }
            ("intensity", _) => {
                once(request.intensity.is_some(), word)?;
                request.intensity = Some(to_percent(value.number(PERCENT)?));
            }
            _ => return Err(word.error(ParseErrorKind::UnknownOption { allowed })),
        }
    }
    Ok(Command::Act(Action::Gesture(request)))
}

/// `look <pitch> <yaw> [ms] [hold=MS|hold=stay]`.
fn look(words: &mut Words<'_>) -> Result<Command, ParseError> {
    let pitch = to_angle(words.number("pitch in mdeg", ANGLE)?);
    let yaw = to_angle(words.number("yaw in mdeg", ANGLE)?);
    let duration = words.optional_number(DURATION)?.map(to_millis);
    let mut hold = None;
    while let Some((name, value, word)) = words.option()? {
        if name != "hold" {
            return Err(word.error(ParseErrorKind::UnknownOption { allowed: "hold" }));
        }
        once(hold.is_some(), word)?;
        hold = Some(if value.lower() == Word::Is("stay") {
            Hold::Stay
        } else {
            Hold::Return(to_millis(value.number(HOLD)?))
        });
    }
    Ok(Command::Act(Action::Look(LookRequest {
        pitch,
        yaw,
        duration,
        hold,
    })))
}

/// `idle on|off|amp <percent>`.
fn idle(words: &mut Words<'_>) -> Result<Command, ParseError> {
    const EXPECTED: &str = "`on`, `off` or `amp`";
    let Some(word) = words.next() else {
        return Err(words.error_here(ParseErrorKind::Missing(EXPECTED)));
    };
    let action = match word.lower() {
        Word::Is("on") => Action::Idle(true),
        Word::Is("off") => Action::Idle(false),
        Word::Is("amp") => Action::IdleAmp(to_percent(words.number("percentage", PERCENT)?)),
        _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: EXPECTED })),
    };
    Ok(Command::Act(action))
}

/// `seed <n>|random`.
fn seed(words: &mut Words<'_>) -> Result<Command, ParseError> {
    const EXPECTED: &str = "a seed or `random`";
    let Some(word) = words.next() else {
        return Err(words.error_here(ParseErrorKind::Missing(EXPECTED)));
    };
    if word.lower() == Word::Is("random") {
        return Ok(Command::Seed(SeedChoice::Random));
    }
    Ok(Command::Seed(SeedChoice::Value(word.number(SEED)? as u32)))
}

/// `servo <axis> [<field> <value>...]`.
fn servo(words: &mut Words<'_>) -> Result<Command, ParseError> {
    const AXES: &str = "`pitch`, `roll` or `yaw`";
    const FIELDS: &str = "`neutral`, `per-degree`, `direction`, `min`, `max` or `limits`";
    let Some(word) = words.next() else {
        return Err(words.error_here(ParseErrorKind::Missing(AXES)));
    };
    let axis = match word.lower() {
        Word::Is("pitch") => Axis::Pitch,
        Word::Is("roll") => Axis::Roll,
        Word::Is("yaw") => Axis::Yaw,
        _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: AXES })),
    };
    let Some(field) = words.next() else {
        return Ok(Command::Servo {
            axis,
            setting: None,
        });
    };
    let pulse = |words: &mut Words<'_>| -> Result<Microseconds, ParseError> {
        Ok(Microseconds(words.number("pulse in us", PULSE)? as u32))
    };
    let setting = match field.lower() {
        Word::Is("neutral") => ServoSetting::Neutral(pulse(words)?),
        Word::Is("min") => ServoSetting::MinPulse(pulse(words)?),
        Word::Is("max") => ServoSetting::MaxPulse(pulse(words)?),
        Word::Is("per-degree") => ServoSetting::PerDegree(NanosPerDegree(
            words.number("ns per degree", PER_DEGREE)? as u32,
        )),
        Word::Is("direction") => {
            const DIRECTIONS: &str = "`normal` or `reversed`";
            let Some(word) = words.next() else {
                return Err(words.error_here(ParseErrorKind::Missing(DIRECTIONS)));
            };
            ServoSetting::Direction(match word.lower() {
                Word::Is("normal") => Direction::Normal,
                Word::Is("reversed") => Direction::Reversed,
                _ => {
                    return Err(word.error(ParseErrorKind::UnknownWord {
                        expected: DIRECTIONS,
                    }));
                }
            })
        }
        Word::Is("limits") => {
            let min = to_angle(words.number("lower limit in mdeg", ANGLE)?);
            let max = to_angle(words.number("upper limit in mdeg", ANGLE)?);
            ServoSetting::Limits(AngleRange { min, max })
        }
        _ => return Err(field.error(ParseErrorKind::UnknownWord { expected: FIELDS })),
    };
    Ok(Command::Servo {
        axis,
        setting: Some(setting),
    })
}

/// An error for an option seen before.
fn once(seen: bool, word: Token<'_>) -> Result<(), ParseError> {
    if seen {
        Err(word.error(ParseErrorKind::DuplicateOption))
    } else {
        Ok(())
    }
}

/// A word of the line with its position.
#[derive(Clone, Copy)]
struct Token<'a> {
    text: &'a [u8],
    start: usize,
}

/// A word compared without regard to ASCII case (`Other` if it matches
/// none of the names the parser asks about).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Word {
    Is(&'static str),
    Other,
}

/// Every word the protocol has, lower case.
const KEYWORDS: [&str; 34] = [
    "help",
    "status",
    "save",
    "load",
    "defaults",
    "stop",
    "nod",
    "shake",
    "tilt",
    "look",
    "center",
    "centre",
    "idle",
    "seed",
    "servo",
    "on",
    "off",
    "amp",
    "random",
    "pitch",
    "roll",
    "yaw",
    "neutral",
    "min",
    "max",
    "per-degree",
    "direction",
    "normal",
    "reversed",
    "limits",
    "stay",
    "hold",
    "cycles",
    "intensity",
];

impl<'a> Token<'a> {
    fn span(&self) -> Span {
        Span {
            start: clamp_u16(self.start),
            end: clamp_u16(self.start + self.text.len()),
        }
    }

    fn error(&self, kind: ParseErrorKind) -> ParseError {
        ParseError {
            kind,
            at: self.span(),
        }
    }

    /// The keyword this word is, ignoring ASCII case.
    fn lower(&self) -> Word {
        KEYWORDS
            .iter()
            .find(|k| k.as_bytes().eq_ignore_ascii_case(self.text))
            .map_or(Word::Other, |k| Word::Is(k))
    }

    /// The word as a whole number in `field`'s range.
    fn number(&self, field: Field) -> Result<i64, ParseError> {
        let value = integer(self.text).ok_or(self.error(ParseErrorKind::NotANumber(field.what)))?;
        if value < field.min || value > field.max {
            return Err(self.error(ParseErrorKind::OutOfRange {
                what: field.what,
                min: field.min,
                max: field.max,
            }));
        }
        Ok(value)
    }

    /// `name=value` split at the first `=`, the name lower-cased.
    fn split_option(&self) -> Option<(&'static str, Token<'a>)> {
        let eq = self.text.iter().position(|&b| b == b'=')?;
        let (name, rest) = self.text.split_at(eq);
        let value = Token {
            text: rest.get(1..).unwrap_or_default(),
            start: self.start + eq + 1,
        };
        let name = Token {
            text: name,
            start: self.start,
        };
        Some((
            match name.lower() {
                Word::Is(k) => k,
                Word::Other => "",
            },
            value,
        ))
    }
}

const fn clamp_u16(v: usize) -> u16 {
    if v > u16::MAX as usize {
        u16::MAX
    } else {
        v as u16
    }
}

/// A decimal integer with an optional sign; `None` if not one or beyond ±2⁶².
fn integer(text: &[u8]) -> Option<i64> {
    let (negative, digits) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, text),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        value = value.checked_mul(10)?.checked_add(i64::from(d - b'0'))?;
        if value > 1 << 62 {
            return None;
        }
    }
    Some(if negative { -value } else { value })
}

/// The words of a line, separated by spaces and tabs.
struct Words<'a> {
    line: &'a [u8],
    pos: usize,
}

impl<'a> Words<'a> {
    fn new(line: &'a [u8]) -> Self {
        Self { line, pos: 0 }
    }

    /// An error at the end of the line (or at the current position).
    fn error_here(&self, kind: ParseErrorKind) -> ParseError {
        let at = clamp_u16(self.line.len());
        ParseError {
            kind,
            at: Span { start: at, end: at },
        }
    }

    fn skip_blanks(&mut self) {
        while let Some(&b) = self.line.get(self.pos) {
            if b != b' ' && b != b'\t' {
                break;
            }
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<Token<'a>> {
        self.skip_blanks();
        let start = self.pos;
        let rest = self.line.get(start..).unwrap_or_default();
        let len = rest
            .iter()
            .position(|&b| b == b' ' || b == b'\t')
            .unwrap_or(rest.len());
        if len == 0 {
            return None;
        }
        Some(Token {
            text: rest.get(..len).unwrap_or_default(),
            start,
        })
    }

    fn next(&mut self) -> Option<Token<'a>> {
        let token = self.peek()?;
        self.pos = token.start + token.text.len();
        Some(token)
    }

    /// A required number.
    fn number(&mut self, what: &'static str, field: Field) -> Result<i64, ParseError> {
        match self.next() {
            Some(token) => token.number(Field { what, ..field }),
            None => Err(self.error_here(ParseErrorKind::Missing(what))),
        }
    }

    /// An optional positional number: absent at the end of the line or
    /// where the options (`name=value`) begin.
    fn optional_number(&mut self, field: Field) -> Result<Option<i64>, ParseError> {
        match self.peek() {
            Some(token) if !token.text.contains(&b'=') => {
                self.next();
                token.number(field).map(Some)
            }
            _ => Ok(None),
        }
    }

    /// The next `name=value` option, if any.
    fn option(&mut self) -> Result<Option<(&'static str, Token<'a>, Token<'a>)>, ParseError> {
        let Some(token) = self.next() else {
            return Ok(None);
        };
        match token.split_option() {
            Some((name, value)) => Ok(Some((name, value, token))),
            None => Err(token.error(ParseErrorKind::Unexpected)),
        }
    }

    /// Nothing may follow.
    fn end(&mut self) -> Result<(), ParseError> {
        match self.next() {
            Some(token) => Err(token.error(ParseErrorKind::Unexpected)),
            None => Ok(()),
        }
    }
}
