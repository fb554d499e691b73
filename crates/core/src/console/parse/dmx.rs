//! `dmx [on | off | address <n>]`.

use crate::command::{Command, DmxSetting};
use crate::dmx::DmxAddress;

use super::error::{ParseError, ParseErrorKind};
use super::words::{Field, Kw, Word, Words};

/// A start address: the personality's ten slots fit the universe.
const ADDRESS: Field = Field::new(
    "DMX address",
    DmxAddress::FIRST.get() as i64,
    DmxAddress::LAST.get() as i64,
);

/// `dmx`, `dmx on|off`, `dmx address <n>`.
pub(super) fn dmx(words: &mut Words<'_>) -> Result<Command, ParseError> {
    const EXPECTED: &str = "`on`, `off` or `address`";
    let Some(word) = words.next() else {
        return Ok(Command::Dmx(None));
    };
    let setting = match word.lower() {
        Word::Is(Kw::On) => DmxSetting::On(true),
        Word::Is(Kw::Off) => DmxSetting::On(false),
        Word::Is(Kw::Address) => {
            let slot = words.number(&ADDRESS)?;
            // In range: the field's bounds are the address's.
            let address = u16::try_from(slot)
                .ok()
                .and_then(DmxAddress::new)
                .unwrap_or(DmxAddress::FIRST);
            DmxSetting::Address(address)
        }
        _ => return Err(word.error(ParseErrorKind::UnknownWord { expected: EXPECTED })),
    };
    Ok(Command::Dmx(Some(setting)))
}
