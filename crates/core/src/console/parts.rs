//! What a board has besides its three servos, as the console answers for
//! it ([`BoardParts`]): a command for a part the board lacks gets
//! `err unavailable …`, never a made-up answer.

use crate::input::InputIds;

/// The optional parts of a board that the console's commands reach. The
/// settings store is not here: a board without one hands the service no
/// storage (`Option<S>`, `None`), and `save`/`load` answer
/// `err unavailable`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoardParts {
    /// The trigger inputs: their numbers (`input <n>`, `status`'s
    /// `inputs=`).
    pub inputs: InputIds,
    /// A DMX512 receiver (`dmx`, `status`'s `dmx=`).
    pub dmx: bool,
    /// A radar's receiver (`radar`).
    pub radar: bool,
}

impl BoardParts {
    /// None of them: servos and a console only.
    pub const NONE: Self = Self {
        inputs: InputIds::NONE,
        dmx: false,
        radar: false,
    };
}
