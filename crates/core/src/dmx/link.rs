//! What the DMX receiver, the frame task and the console share.
//!
//! Each part is a [`SharedCell`] of a few bytes: the frame task reads it
//! between frames without a panic path and without waiting for anyone.

use crate::shared::SharedCell;

use super::{Counters, Cue, DmxAddress, DmxSettings};

/// The latest good frame's cue, and how many good frames there have been
/// (the frame task tells a new cue by the count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Latest {
    /// Good frames so far (wrapping).
    pub seq: u32,
    /// The latest good frame's cue.
    pub cue: Cue,
}

/// The DMX signal as the frame task last judged it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Signal {
    /// No good frame for a second (or never): the head plays on its own.
    #[default]
    Lost,
    /// Good frames arrive: the head follows them.
    Ok,
    /// DMX is switched off (`dmx off`).
    Off,
}

impl Signal {
    /// The word in `status` and `dmx`.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Off => "off",
            Self::Lost => "lost",
            Self::Ok => "ok",
        }
    }
}

/// What the receiver has received: the latest cue and the counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Received {
    latest: Latest,
    counters: Counters,
}

/// The shared DMX state; lives in a `static`. All zero at first (off,
/// nothing received), so that it takes no flash: the boot sets the
/// settings.
pub struct DmxLink {
    /// Whether on, and the address less one.
    settings: SharedCell<(bool, u16)>,
    received: SharedCell<Received>,
    signal: SharedCell<Signal>,
}

impl DmxLink {
    /// Off until the settings are set ([`set`](Self::set)), nothing
    /// received.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            settings: SharedCell::new((false, 0)),
            received: SharedCell::new(Received {
                latest: Latest {
                    seq: 0,
                    cue: Cue::ZERO,
                },
                counters: Counters::ZERO,
            }),
            signal: SharedCell::new(Signal::Lost),
        }
    }

    /// The console (and the boot): DMX on or off, and the address.
    pub fn set(&self, settings: DmxSettings) {
        let raw = (settings.on, settings.address.get() - 1);
        self.settings.set(raw);
    }

    /// The settings in effect.
    pub fn settings(&self) -> DmxSettings {
        let (on, less_one) = self.settings.get();
        DmxSettings {
            on,
            address: DmxAddress::new(less_one + 1).unwrap_or(DmxAddress::FIRST),
        }
    }

    /// The receiver, at a frame's end: the counters, and the frame's cue if
    /// it was a good one.
    pub fn record(&self, cue: Option<Cue>, counters: Counters) {
        self.received.update(|received| {
            if let Some(cue) = cue {
                received.latest = Latest {
                    seq: received.latest.seq.wrapping_add(1),
                    cue,
                };
            }
            received.counters = counters;
        });
    }

    /// The frame task: whether DMX is on, and the latest cue.
    pub fn latest(&self) -> (bool, Latest) {
        let on = self.settings.get().0;
        (on, self.received.get().latest)
    }

    /// The console: what became of the frames so far.
    pub fn counters(&self) -> Counters {
        self.received.get().counters
    }

    /// The frame task: the signal as it judges it.
    pub fn set_signal(&self, signal: Signal) {
        self.signal.set(signal);
    }

    /// The console: the signal as the frame task last judged it.
    pub fn signal(&self) -> Signal {
        self.signal.get()
    }
}

impl Default for DmxLink {
    fn default() -> Self {
        Self::new()
    }
}

impl core::fmt::Debug for DmxLink {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("DmxLink")
            .field("settings", &self.settings())
            .field("signal", &self.signal())
            .finish_non_exhaustive()
    }
}
