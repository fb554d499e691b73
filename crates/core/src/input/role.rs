//! What an input is ([`InputRole`], part of the command vocabulary), and
//! the pull resistor its source sets up for it ([`Pull`]).

pub use crate::command::InputRole;

use super::{BUTTON_DEBOUNCE, Debounce, PRESENCE_DEBOUNCE};

/// The pull resistor an input's pin needs for its role.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Pull {
    /// Pulled up: a button to ground reads high until pressed.
    Up,
    /// Pulled down: a sensor unplugged, or a wire broken, reads low
    /// (nobody), so the head rests rather than wakes at random.
    Down,
}

impl InputRole {
    /// The pin's pull for this role (an input that is off is pulled down:
    /// a floating pin stays quiet).
    #[must_use]
    pub const fn pull(&self) -> Pull {
        match self {
            Self::Button(_) => Pull::Up,
            Self::Off | Self::Presence { .. } => Pull::Down,
        }
    }

    /// The level at which the input is active (`true`: high).
    #[must_use]
    pub const fn active_high(&self) -> bool {
        !matches!(self, Self::Button(_))
    }

    /// How its level becomes an edge (`None`: off, never counts): a
    /// button's press at once, its bounces after it ignored; a presence
    /// sensor's level once it has held.
    #[must_use]
    pub const fn debounce(&self) -> Option<Debounce> {
        match self {
            Self::Off => None,
            Self::Button(_) => Some(Debounce::Leading(BUTTON_DEBOUNCE.0 as u64 * 1000)),
            Self::Presence { .. } => Some(Debounce::Hold(PRESENCE_DEBOUNCE.0 as u64 * 1000)),
        }
    }

    /// Whether it is a presence sensor.
    #[must_use]
    pub const fn is_presence(&self) -> bool {
        matches!(self, Self::Presence { .. })
    }

    /// Its word in the console (`off`, `button`, `presence`).
    #[must_use]
    pub const fn word(&self) -> &'static str {
        match self {
            Self::Off => "off",
            Self::Button(_) => "button",
            Self::Presence { .. } => "presence",
        }
    }
}
