//! `look duck <percent>`: how much a held look ducks the idle on its axes.

use crate::command::{Command, Percent};

use super::error::ParseError;
use super::words::{Field, Kw, Word, Words};

const PERCENT: Field = Field::new("percentage", 0, 100);

/// Whether the next word is `duck` (after `look`).
pub(super) fn follows(words: &mut Words<'_>) -> bool {
    words
        .peek()
        .is_some_and(|word| word.lower() == Word::Is(Kw::Duck))
}

/// `look duck <percent>` (after the word `look`).
pub(super) fn look_duck(words: &mut Words<'_>) -> Result<Command, ParseError> {
    words.next();
    let percent = words.number(&PERCENT)?;
    Ok(Command::LookDuck(
        Percent::new(percent as u8).unwrap_or(Percent::FULL),
    ))
}
