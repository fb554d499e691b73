//! One line of the console protocol → a [`Command`].
//!
//! Words are separated by spaces or tabs and compared without regard to
//! ASCII case; numbers are decimal integers in the project's units;
//! options are `name=value` words after the positional arguments. The
//! parser checks the syntax and that each number fits its type (whether a
//! value suits the head is for the behaviour and the settings); it never
//! panics and allocates nothing. The grammar: `docs/user/protocol.md`.
//!
//! ```
//! use idle_head_core::command::{Action, Command, GestureKind};
//! use idle_head_core::console::parse;
//! use idle_head_core::{Angle, Millis};
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
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The console's grammar”).

use crate::axis::Axis;
use crate::command::{
    Action, Command, GestureKind, GestureRequest, Hold, LookRequest, Percent, SeedChoice,
    ServoSetting,
};
use crate::servo::{Direction, NanosPerDegree, ServoRate};
use crate::units::{Angle, AngleRange, Microseconds, Millis};

mod dmx;
mod duck;
mod error;
mod input;
mod line;
mod rest;
mod track;
mod words;

pub use error::{ParseError, ParseErrorKind, Span};
pub use line::ActionLine;
pub use words::KEYWORDS;
use words::{Field, Kw, Token, Word, Words, once};

/// Parses one line (without its line ending); the grammar is in this
/// module's source and, for users, in `docs/user/protocol.md`.
///
/// # Errors
/// A [`ParseError`] naming the first problem and the word it is in.
pub fn parse(line: &[u8]) -> Result<Command, ParseError> {
    let mut words = Words::new(line);
    let Some(first) = words.next() else {
        return Err(words.error_here(ParseErrorKind::Empty));
    };
    // The keyword is looked up once.
    let keyword = first.lower();
    let command = if keyword == Word::Is(Kw::Idle) && words.peek().is_none() {
        Command::IdleQuery
    } else if let Some(action) = motion(first, keyword, &mut words)? {
        Command::Act(action)
    } else {
        match keyword {
            Word::Is(Kw::Help) => Command::Help,
            Word::Is(Kw::Status) => Command::Status,
            Word::Is(Kw::Save) => Command::Save,
            Word::Is(Kw::Load) => Command::Load,
            Word::Is(Kw::Defaults) => Command::Defaults,
            Word::Is(Kw::Seed) => seed(&mut words)?,
            Word::Is(Kw::Servo) => servo(&mut words)?,
            Word::Is(Kw::Input) => input::input(&mut words)?,
            Word::Is(Kw::Rest) => rest::rest(&mut words)?,
            Word::Is(Kw::Look) => duck::look_duck(&mut words)?,
            Word::Is(Kw::Watch) => watch(&mut words)?,
            Word::Is(Kw::Dmx) => dmx::dmx(&mut words)?,
            Word::Is(Kw::Radar) => track::radar(&mut words)?,
            Word::Is(Kw::Track) => track::track(&mut words)?,
            _ => return Err(first.error(ParseErrorKind::UnknownCommand)),
        }
    };
    words.end()?;
    Ok(command)
}

/// The motion command that starts with `first`, if it is one (its words
/// up to the end, not checked for more): a gesture, `look`, `center`,
/// `idle`, `stop`, `rest` or `wake`. `None` for any other first word (and
/// for the settings `rest` and `look` take: `rest after …`, `look duck …`).
/// `keyword` is `first`'s, looked up by the caller (a lookup is a bisection
/// of all the keywords).
fn motion(
    first: Token<'_>,
    keyword: Word,
    words: &mut Words<'_>,
) -> Result<Option<Action>, ParseError> {
    if let Some(kind) = first.gesture() {
        return gesture(words, kind).map(Some);
    }
    let action = match keyword {
        Word::Is(Kw::Stop) => Action::Stop,
        Word::Is(Kw::Look) if !duck::follows(words) => look(words)?,
        Word::Is(Kw::Center | Kw::Centre) => Action::Center {
            duration: words.optional_number(&DURATION)?.map(to_millis),
        },
        Word::Is(Kw::Idle) => idle(words)?,
        Word::Is(Kw::Rest) if words.peek().is_none() => Action::Rest,
        Word::Is(Kw::Wake) => Action::Wake { toward: None },
        _ => return Ok(None),
    };
    Ok(Some(action))
}

/// The range of an angle or an amplitude in m°: the `i32` range without
/// `i32::MIN`.
const MDEG: (i64, i64) = (i32::MIN as i64 + 1, i32::MAX as i64);
const AMPLITUDE: Field = Field::new("amplitude in mdeg", MDEG.0, MDEG.1);
const PITCH: Field = Field::new("pitch in mdeg", MDEG.0, MDEG.1);
const YAW: Field = Field::new("yaw in mdeg", MDEG.0, MDEG.1);
const LOWER_LIMIT: Field = Field::new("lower limit in mdeg", MDEG.0, MDEG.1);
const UPPER_LIMIT: Field = Field::new("upper limit in mdeg", MDEG.0, MDEG.1);
const DURATION: Field = Field::new("duration in ms", 1, u32::MAX as i64);
const HOLD: Field = Field::new("hold in ms", 0, u32::MAX as i64);
const CYCLES: Field = Field::new("cycles", 1, u8::MAX as i64);
const PERCENT: Field = Field::new("percentage", 0, 100);
const SEED: Field = Field::new("seed", 0, u32::MAX as i64);
const PULSE: Field = Field::new("pulse in us", 0, u32::MAX as i64);
const PER_DEGREE: Field = Field::new("ns per degree", 0, u32::MAX as i64);
const WATCH_HZ: Field = Field::new("lines a second", 1, crate::console::MAX_WATCH_HZ as i64);
const RATE_HZ: Field = Field::new(
    "servo rate in Hz",
    ServoRate::MIN.hz() as i64,
    ServoRate::MAX.hz() as i64,
);

fn to_angle(v: i64) -> Angle {
    Angle::from_millidegrees(v as i32)
}

fn to_millis(v: i64) -> Millis {
    Millis(v as u32)
}

fn to_percent(v: i64) -> Percent {
    Percent::new(v as u8).unwrap_or(Percent::FULL)
}

/// `<gesture> [amp] [ms] [cycles=N] [intensity=P]`, any row of the
/// [gesture table](crate::gestures); `cycles=` where the gesture may have
/// more than one.
fn gesture(words: &mut Words<'_>, kind: GestureKind) -> Result<Action, ParseError> {
    let mut request = GestureRequest::new(kind);
    request.amplitude = words.optional_number(&AMPLITUDE)?.map(to_angle);
    request.duration = words.optional_number(&DURATION)?.map(to_millis);
    let cycles = kind.row().max_cycles > 1;
    let allowed = if cycles {
        "cycles, intensity"
    } else {
        "intensity"
    };
    while let Some((name, value, word)) = words.option()? {
        match name {
            Word::Is(Kw::Cycles) if cycles => {
                once(request.cycles.is_some(), word)?;
                request.cycles = Some(value.number(&CYCLES)? as u8);
            }
            Word::Is(Kw::Intensity) => {
                once(request.intensity.is_some(), word)?;
                request.intensity = Some(to_percent(value.number(&PERCENT)?));
            }
            _ => return Err(word.error(ParseErrorKind::UnknownOption { allowed })),
        }
    }
    Ok(Action::Gesture(request))
}

/// `look <pitch> <yaw> [ms] [hold=MS|hold=stay]`.
fn look(words: &mut Words<'_>) -> Result<Action, ParseError> {
    let pitch = to_angle(words.number(&PITCH)?);
    let yaw = to_angle(words.number(&YAW)?);
    let duration = words.optional_number(&DURATION)?.map(to_millis);
    let mut hold = None;
    while let Some((name, value, word)) = words.option()? {
        if name != Word::Is(Kw::Hold) {
            return Err(word.error(ParseErrorKind::UnknownOption { allowed: "hold" }));
        }
        once(hold.is_some(), word)?;
        hold = Some(if value.lower() == Word::Is(Kw::Stay) {
            Hold::Stay
        } else {
            Hold::Return(to_millis(value.number(&HOLD)?))
        });
    }
    Ok(Action::Look(LookRequest {
        pitch,
        yaw,
        duration,
        hold,
    }))
}

/// `idle on|off|amp <percent>`.
fn idle(words: &mut Words<'_>) -> Result<Action, ParseError> {
    const EXPECTED: &str = "`on`, `off` or `amp`";
    let Some(word) = words.next() else {
        return Err(words.error_here(ParseErrorKind::Missing(EXPECTED)));
    };
    let action = match word.lower() {
        Word::Is(Kw::On) => Action::Idle(true),
        Word::Is(Kw::Off) => Action::Idle(false),
        Word::Is(Kw::Amp) => Action::IdleAmp(to_percent(words.number(&PERCENT)?)),
        _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: EXPECTED })),
    };
    Ok(action)
}

/// `seed [<n>|random|board|paper]` (alone: the seed in use).
fn seed(words: &mut Words<'_>) -> Result<Command, ParseError> {
    let Some(word) = words.next() else {
        return Ok(Command::SeedQuery);
    };
    let choice = match word.lower() {
        Word::Is(Kw::Random) => SeedChoice::Random,
        Word::Is(Kw::Board) => SeedChoice::Board,
        Word::Is(Kw::Paper) => SeedChoice::Paper,
        _ => SeedChoice::Value(word.number(&SEED)? as u32),
    };
    Ok(Command::Seed(choice))
}

/// `watch <hz>|off`.
fn watch(words: &mut Words<'_>) -> Result<Command, ParseError> {
    const EXPECTED: &str = "lines a second or `off`";
    let Some(word) = words.next() else {
        return Err(words.error_here(ParseErrorKind::Missing(EXPECTED)));
    };
    if word.lower() == Word::Is(Kw::Off) {
        return Ok(Command::Watch(None));
    }
    Ok(Command::Watch(Some(word.number(&WATCH_HZ)? as u8)))
}

/// `servo <axis> [<field> <value>...]`, `servo rate [<hz>]`.
fn servo(words: &mut Words<'_>) -> Result<Command, ParseError> {
    const AXES: &str = "`pitch`, `roll`, `yaw` or `rate`";
    const FIELDS: &str = "`neutral`, `per-degree`, `direction`, `min`, `max` or `limits`";
    let Some(word) = words.next() else {
        return Err(words.error_here(ParseErrorKind::Missing(AXES)));
    };
    let axis = match word.lower() {
        Word::Is(Kw::Pitch) => Axis::Pitch,
        Word::Is(Kw::Roll) => Axis::Roll,
        Word::Is(Kw::Yaw) => Axis::Yaw,
        Word::Is(Kw::Rate) => {
            let hz = words.optional_number(&RATE_HZ)?;
            // Within the field's range: a rate.
            return Ok(Command::ServoRate(
                hz.and_then(|hz| ServoRate::new(hz as u16)),
            ));
        }
        _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: AXES })),
    };
    let Some(field) = words.next() else {
        return Ok(Command::Servo {
            axis,
            setting: None,
        });
    };
    let pulse = |words: &mut Words<'_>| -> Result<Microseconds, ParseError> {
        Ok(Microseconds(words.number(&PULSE)? as u32))
    };
    let setting = match field.lower() {
        Word::Is(Kw::Neutral) => ServoSetting::Neutral(pulse(words)?),
        Word::Is(Kw::Min) => ServoSetting::MinPulse(pulse(words)?),
        Word::Is(Kw::Max) => ServoSetting::MaxPulse(pulse(words)?),
        Word::Is(Kw::PerDegree) => {
            ServoSetting::PerDegree(NanosPerDegree(words.number(&PER_DEGREE)? as u32))
        }
        Word::Is(Kw::Direction) => {
            const DIRECTIONS: &str = "`normal` or `reversed`";
            let Some(word) = words.next() else {
                return Err(words.error_here(ParseErrorKind::Missing(DIRECTIONS)));
            };
            ServoSetting::Direction(match word.lower() {
                Word::Is(Kw::Normal) => Direction::Normal,
                Word::Is(Kw::Reversed) => Direction::Reversed,
                _ => {
                    return Err(word.error(ParseErrorKind::UnknownWord {
                        expected: DIRECTIONS,
                    }));
                }
            })
        }
        Word::Is(Kw::Limits) => {
            let min = to_angle(words.number(&LOWER_LIMIT)?);
            let max = to_angle(words.number(&UPPER_LIMIT)?);
            ServoSetting::Limits(AngleRange { min, max })
        }
        _ => return Err(field.error(ParseErrorKind::UnknownWord { expected: FIELDS })),
    };
    Ok(Command::Servo {
        axis,
        setting: Some(setting),
    })
}
