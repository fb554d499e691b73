//! `radar [on|off]`, `track [on|off|height <mm>|mount <mdeg>|prefer …]`.

use crate::command::{Command, TrackSetting};
use crate::track::{HEIGHT, MOUNT, Prefer};
use crate::units::{Angle, Millimetres};

use super::error::{ParseError, ParseErrorKind};
use super::words::{Field, Kw, Word, Words};

const HEIGHT_MM: Field = Field::new("height in mm", HEIGHT.0 as i64, HEIGHT.1 as i64);
const MOUNT_MDEG: Field = Field::new("yaw in mdeg", MOUNT.0 as i64, MOUNT.1 as i64);

/// `on` or `off` (or nothing: `None`).
fn switch(words: &mut Words<'_>, expected: &'static str) -> Result<Option<bool>, ParseError> {
    let Some(word) = words.next() else {
        return Ok(None);
    };
    match word.lower() {
        Word::Is(Kw::On) => Ok(Some(true)),
        Word::Is(Kw::Off) => Ok(Some(false)),
        _ => Err(word.error(ParseErrorKind::UnknownWord { expected })),
    }
}

/// `radar`, `radar on|off`.
pub(super) fn radar(words: &mut Words<'_>) -> Result<Command, ParseError> {
    Ok(Command::Radar(switch(words, "`on` or `off`")?))
}

/// `track`, `track on|off|height <mm>|mount <mdeg>|prefer nearest|newest`.
pub(super) fn track(words: &mut Words<'_>) -> Result<Command, ParseError> {
    const EXPECTED: &str = "`on`, `off`, `height`, `mount` or `prefer`";
    let Some(word) = words.next() else {
        return Ok(Command::Track(None));
    };
    let setting = match word.lower() {
        Word::Is(Kw::On) => TrackSetting::Gaze(true),
        Word::Is(Kw::Off) => TrackSetting::Gaze(false),
        Word::Is(Kw::Height) => TrackSetting::Height(Millimetres(words.number(&HEIGHT_MM)? as i32)),
        Word::Is(Kw::Mount) => {
            TrackSetting::Mount(Angle::from_millidegrees(words.number(&MOUNT_MDEG)? as i32))
        }
        Word::Is(Kw::Prefer) => {
            const WHOM: &str = "`nearest` or `newest`";
            let Some(word) = words.next() else {
                return Err(words.error_here(ParseErrorKind::Missing(WHOM)));
            };
            TrackSetting::Prefer(match word.lower() {
                Word::Is(Kw::Nearest) => Prefer::Nearest,
                Word::Is(Kw::Newest) => Prefer::Newest,
                _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: WHOM })),
            })
        }
        _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: EXPECTED })),
    };
    Ok(Command::Track(Some(setting)))
}
