//! `look duck [<percent>]`: how much a held look ducks the idle on its
//! axes (alone: the duck in effect).

use crate::command::Command;

use super::error::ParseError;
use super::words::{Kw, Word, Words};
use super::{PERCENT, to_percent};

/// Whether the next word is `duck` (after `look`).
pub(super) fn follows(words: &mut Words<'_>) -> bool {
    words
        .peek()
        .is_some_and(|word| word.lower() == Word::Is(Kw::Duck))
}

/// `look duck [<percent>]` (after the word `look`; alone: the duck in
/// effect).
pub(super) fn look_duck(words: &mut Words<'_>) -> Result<Command, ParseError> {
    words.next();
    if words.peek().is_none() {
        return Ok(Command::LookDuck(None));
    }
    Ok(Command::LookDuck(Some(to_percent(words.number(&PERCENT)?))))
}
