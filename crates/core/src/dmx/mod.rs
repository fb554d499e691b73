//! DMX512 input: a lighting console drives the head like any fixture.
//!
//! - [`Decoder`]: a universe's bytes and breaks (as a UART reports them)
//!   in, the head's few slots out; every frame that is not used is counted
//!   ([`Counters`]) and ignored. Nothing is buffered but the slots of the
//!   personality: a frame of 513 bytes goes through ten bytes of state.
//! - [`Cue`]: the personality, the slots taken apart (table below);
//!   [`Trigger`]: the gesture trigger's bands.
//! - [`DmxLink`]: what the receiver, the frame task and the console share
//!   (the latest cue, the counters, whether DMX is on and at which
//!   address).
//!
//! What the head does with a cue (the show layer over the idle, the
//! gestures it fires, signal loss) is [`crate::behaviour::show`]'s.
//!
//! # The personality
//!
//! Ten slots from the head's start address (`dmx address`, 1 to 503):
//!
//! | slot | meaning |
//! |---|---|
//! | 1–2 | yaw, 16 bit (coarse, fine): 0 the lower angle limit, 65 535 the upper |
//! | 3–4 | pitch, likewise |
//! | 5–6 | roll, likewise |
//! | 7 | position mix: 0 the head's own motion only, 255 the DMX pose fully |
//! | 8 | gesture trigger: 0–9 none, 10–29 nod, 30–49 shake, 50–69 tilt, 70–89 center, 90–255 none |
//! | 9 | idle intensity, 0–255 → 0–100 % |
//! | 10 | reserved (wake and rest, once the head has them): ignored |
//!
//! # Frames
//!
//! A frame is a break, the start code and up to 512 slots. Only start code
//! 0 (dimmer data) is used; a frame with another start code (RDM, text,
//! system information) is counted and skipped. A frame that ends before
//! slot 9 of the personality is *short*, one with more than 512 slots
//! *long*, one in which the UART saw a framing, parity or overrun error
//! *garbled*: each is counted and ignored.

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
