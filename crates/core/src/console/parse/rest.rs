//! `rest after <seconds>|never`, `rest pose <pitch> <roll> <yaw>`,
//! `rest relax on|off`; any of `rest after`, `rest pose` and `rest relax`
//! alone shows the rest settings (`rest` alone is a motion: the head
//! rests).

use crate::command::{Command, MAX_REST_AFTER, RestAfter, RestSetting};
use crate::units::Angle;

use super::error::{ParseError, ParseErrorKind};
use super::words::{Field, Kw, Word, Words};
use super::{MDEG, PITCH, YAW, to_angle};

const SECONDS: Field = Field::new("seconds", 1, MAX_REST_AFTER as i64);
const ROLL: Field = Field::new("roll in mdeg", MDEG.0, MDEG.1);

/// `rest after|pose|relax …` (after the word `rest`).
pub(super) fn rest(words: &mut Words<'_>) -> Result<Command, ParseError> {
    const EXPECTED: &str = "`after`, `pose` or `relax`";
    let Some(word) = words.next() else {
        return Err(words.error_here(ParseErrorKind::Missing(EXPECTED)));
    };
    let field = word.lower();
    if matches!(field, Word::Is(Kw::After | Kw::Pose | Kw::Relax)) && words.peek().is_none() {
        return Ok(Command::Rest(None));
    }
    let setting = match field {
        Word::Is(Kw::After) => match words.peek() {
            Some(w) if w.lower() == Word::Is(Kw::Never) => {
                words.next();
                RestSetting::After(RestAfter::Never)
            }
            _ => RestSetting::After(RestAfter::Seconds(words.number(&SECONDS)? as u32)),
        },
        Word::Is(Kw::Pose) => {
            let mut angle =
                |field| -> Result<Angle, ParseError> { Ok(to_angle(words.number(field)?)) };
            RestSetting::Pose([angle(&PITCH)?, angle(&ROLL)?, angle(&YAW)?])
        }
        Word::Is(Kw::Relax) => {
            const SWITCH: &str = "`on` or `off`";
            let Some(word) = words.next() else {
                return Err(words.error_here(ParseErrorKind::Missing(SWITCH)));
            };
            match word.lower() {
                Word::Is(Kw::On) => RestSetting::Relax(true),
                Word::Is(Kw::Off) => RestSetting::Relax(false),
                _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: SWITCH })),
            }
        }
        _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: EXPECTED })),
    };
    Ok(Command::Rest(Some(setting)))
}
