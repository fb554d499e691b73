//! `input <n> [off | button <action line> | presence [<yaw_mdeg>]]`.
//!
//! A button's action is any motion line (what `Command::Act` parses to),
//! parsed from the rest of the line by the parser's own motion grammar (a
//! motion holds no other command: a line never nests).

use crate::command::{Command, InputRole};

use super::error::{ParseError, ParseErrorKind};
use super::words::{Field, Kw, Word, Words};
use super::{YAW, to_angle};

/// An input's number, as the console names it: which numbers a board has
/// is the board's (`InputIds`), and the service refuses the others.
const INPUT: Field = Field::new("input", 0, u8::MAX as i64);
/// Where a presence sensor looks: a yaw, as `look` takes it.
const DIRECTION: Field = YAW;

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
            toward: words.optional_number(&DIRECTION)?.map(to_angle),
        },
        Word::Is(Kw::Button) => {
            // The motion command: the rest of the line, on the same words.
            let Some(first) = words.next() else {
                return Err(words.error_here(ParseErrorKind::Missing(MOTION)));
            };
            let Some(action) = super::motion(first, first.lower(), words)? else {
                return Err(first.error(ParseErrorKind::UnknownWord { expected: MOTION }));
            };
            InputRole::Button(action)
        }
        _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: ROLES })),
    };
    Ok(Command::Input {
        input,
        role: Some(role),
    })
}
