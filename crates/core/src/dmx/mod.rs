//! DMX512 input: a lighting console drives the head like any fixture.
//!
//! The head takes [`FOOTPRINT`] slots from its [`DmxAddress`] (its
//! personality: the pose, the mix, a gesture trigger, the idle intensity);
//! the [`Decoder`] keeps those slots of each frame and counts every frame by
//! what became of it ([`Counters`]); only a good frame (start code 0, long
//! enough, no receive error) gives a [`Cue`].
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “DMX512”).

mod decoder;
mod link;
mod personality;

pub use decoder::{Counters, Decoder};
pub use link::{DmxLink, Latest, Signal};
pub use personality::{Cue, Trigger};

/// Slots of the personality, the reserved one included.
pub const FOOTPRINT: u16 = 10;
/// Slots a frame must reach for the head to use it (slot 10 is reserved).
pub const USED: u16 = 9;
/// Slots of a universe.
pub const UNIVERSE: u16 = 512;

/// The first slot of the head's personality: 1 to 503, so that all ten
/// slots fit in the universe.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DmxAddress(u16);

impl DmxAddress {
    /// Slot 1, the default.
    pub const FIRST: Self = Self(1);
    /// The highest start address: 503, whose slot 10 is slot 512.
    pub const LAST: Self = Self(UNIVERSE - FOOTPRINT + 1);

    /// `slot`, if it is a start address (`1..=503`).
    #[must_use]
    pub const fn new(slot: u16) -> Option<Self> {
        if slot >= Self::FIRST.0 && slot <= Self::LAST.0 {
            Some(Self(slot))
        } else {
            None
        }
    }

    /// The slot number, 1-based.
    #[must_use]
    pub const fn get(self) -> u16 {
        self.0
    }
}

impl Default for DmxAddress {
    fn default() -> Self {
        Self::FIRST
    }
}

/// The DMX settings: whether the receiver listens, and where the head is
/// patched.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DmxSettings {
    /// Whether DMX drives the head (`dmx on|off`).
    pub on: bool,
    /// The start address (`dmx address <n>`).
    pub address: DmxAddress,
}

impl DmxSettings {
    /// On, at address 1: with no signal it changes nothing, so a head
    /// works the moment it is patched.
    pub const DEFAULT: Self = Self {
        on: true,
        address: DmxAddress::FIRST,
    };
}

impl Default for DmxSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}
