//! `input <n> [off | button <action line> | presence [<yaw_mdeg>]]`.
//!
//! A button's action is any motion line (what `Command::Act` parses to),
//! parsed by the same parser from the rest of the line: its errors point
//! at the word in the whole line.

use crate::command::{Command, InputRole};
use crate::input::{FIRST_INPUT, INPUTS};
use crate::units::Angle;

use super::error::{ParseError, ParseErrorKind, Span};
use super::words::{Field, Kw, Word, Words};

/// The inputs' numbers, as the console names them (GP2 to GP5).
const INPUT: Field = Field::new(
    "input (2 to 5)",
    FIRST_INPUT as i64,
    FIRST_INPUT as i64 + INPUTS as i64 - 1,
);
const DIRECTION: Field = Field::new("yaw in mdeg", i32::MIN as i64 + 1, i32::MAX as i64);

/// What `button` takes.
const MOTION: &str = "a motion command (a gesture, look, center, idle, stop, rest or wake)";

/// `input <n> …` (after the word `input`).
pub(super) fn input(words: &mut Words<'_>) -> Result<Command, ParseError> {
    const ROLES: &str = "`off`, `button` or `presence`";
    let input = words.number(&INPUT)? as u8;
    let Some(word) = words.next() else {
        return Ok(Command::Input { input, role: None });
    };
    let role = match word.lower() {
        Word::Is(Kw::Off) => InputRole::Off,
        Word::Is(Kw::Presence) => InputRole::Presence {
            toward: words
                .optional_number(&DIRECTION)?
                .map(|v| Angle::from_millidegrees(v as i32)),
        },
        Word::Is(Kw::Button) => {
            let (line, at) = words.rest();
            if line.is_empty() {
                return Err(words.error_here(ParseErrorKind::Missing(MOTION)));
            }
            InputRole::Button(action(line, at)?)
        }
        _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: ROLES })),
    };
    Ok(Command::Input {
        input,
        role: Some(role),
    })
}

/// The motion command of `line`, which starts at byte `at` of the whole
/// line (its errors are moved there). Not the whole parser: a motion
/// holds no other command, so a line never nests.
fn action(line: &[u8], at: usize) -> Result<crate::command::Action, ParseError> {
    let moved = |e: ParseError| ParseError {
        kind: e.kind,
        at: Span {
            start: shift(e.at.start, at),
            end: shift(e.at.end, at),
        },
    };
    let mut words = Words::new(line);
    let Some(first) = words.next() else {
        return Err(moved(words.error_here(ParseErrorKind::Missing(MOTION))));
    };
    let Some(action) = super::motion(first, &mut words).map_err(moved)? else {
        return Err(moved(
            first.error(ParseErrorKind::UnknownWord { expected: MOTION }),
        ));
    };
    words.end().map_err(moved)?;
    Ok(action)
}

/// `position + offset`, within `u16`.
fn shift(position: u16, offset: usize) -> u16 {
    u16::try_from(usize::from(position).saturating_add(offset)).unwrap_or(u16::MAX)
}
