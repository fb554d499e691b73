//! What the DMX receiver, the frame task and the console share.
//!
//! Each part is an embassy-sync blocking `Mutex` over a `Cell`: a critical
//! section around a copy of a few bytes, no borrow that could fail, so the
//! frame task reads it between frames without a panic path and without
//! waiting for anyone.

use core::cell::Cell;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

use super::{Counters, Cue, DmxSettings};

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
    /// DMX is switched off (`dmx off`).
    Off,
    /// No good frame for a second (or never): the head plays on its own.
    #[default]
    Lost,
    /// Good frames arrive: the head follows them.
    Ok,
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

/// The shared DMX state; lives in a `static`.
pub struct DmxLink {
    settings: Mutex<CriticalSectionRawMutex, Cell<DmxSettings>>,
    latest: Mutex<CriticalSectionRawMutex, Cell<Latest>>,
    counters: Mutex<CriticalSectionRawMutex, Cell<Counters>>,
    signal: Mutex<CriticalSectionRawMutex, Cell<Signal>>,
}

impl DmxLink {
    /// The built-in settings ([`DmxSettings::DEFAULT`]), nothing received.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            settings: Mutex::new(Cell::new(DmxSettings::DEFAULT)),
            latest: Mutex::new(Cell::new(Latest {
                seq: 0,
                cue: Cue {
                    pose: [0; 3],
                    mix: 0,
                    trigger: 0,
                    intensity: 0,
                },
            })),
            counters: Mutex::new(Cell::new(Counters {
                good: 0,
                short: 0,
                long: 0,
                bad_start: 0,
                garbled: 0,
            })),
            signal: Mutex::new(Cell::new(Signal::Lost)),
        }
    }

    /// The console (and the boot): DMX on or off, and the address.
    pub fn set(&self, settings: DmxSettings) {
        self.settings.lock(|cell| cell.set(settings));
    }

    /// The settings in effect.
    pub fn settings(&self) -> DmxSettings {
        self.settings.lock(Cell::get)
    }

    /// The receiver: a good frame's cue, and the counters with it.
    pub fn publish(&self, cue: Cue, counters: Counters) {
        self.latest.lock(|cell| {
            let seq = cell.get().seq.wrapping_add(1);
            cell.set(Latest { seq, cue });
        });
        self.count(counters);
    }

    /// The receiver: the counters after a frame that was not used.
    pub fn count(&self, counters: Counters) {
        self.counters.lock(|cell| cell.set(counters));
    }

    /// The frame task: whether DMX is on, and the latest cue.
    pub fn latest(&self) -> (bool, Latest) {
        let on = self.settings.lock(Cell::get).on;
        (on, self.latest.lock(Cell::get))
    }

    /// The console: what became of the frames so far.
    pub fn counters(&self) -> Counters {
        self.counters.lock(Cell::get)
    }

    /// The frame task: the signal as it judges it.
    pub fn set_signal(&self, signal: Signal) {
        self.signal.lock(|cell| cell.set(signal));
    }

    /// The console: the signal as the frame task last judged it.
    pub fn signal(&self) -> Signal {
        self.signal.lock(Cell::get)
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
