//! What the tracker's receiver, the frame task, the input task and the
//! console share.
//!
//! Each part is a [`SharedCell`] of a few dozen bytes: the frame task reads
//! it between frames without a panic path and without waiting for the
//! receiver (an interrupt) or the console.

use crate::shared::SharedCell;

use super::{Counters, Sighting, TrackSettings};

/// What the receiver has published.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Received {
    /// The latest sighting.
    pub sighting: Sighting,
    /// Sightings so far (wrapping).
    pub seq: u32,
    /// Sightings with somebody in them so far (wrapping): the input task
    /// tells presence by its change.
    pub seen: u32,
    /// The latest sighting was taken by the frame task.
    pub taken: bool,
    /// The tracker's counters, with the link's `dropped`.
    pub counters: Counters,
}

/// The shared tracker state; lives in a `static`. All zero at first (off,
/// nothing received).
pub struct TrackLink {
    settings: SharedCell<TrackSettings>,
    received: SharedCell<Received>,
}

impl TrackLink {
    /// The built-in settings (radar off), nothing received.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            settings: SharedCell::new(TrackSettings::DEFAULT),
            received: SharedCell::new(Received {
                sighting: Sighting::NOBODY,
                seq: 0,
                seen: 0,
                taken: true,
                counters: Counters {
                    good: 0,
                    bad: 0,
                    dropped: 0,
                    skipped: 0,
                },
            }),
        }
    }

    /// The boot and the console: the settings in effect.
    pub fn set(&self, settings: TrackSettings) {
        self.settings.set(settings);
    }

    /// The settings in effect.
    pub fn settings(&self) -> TrackSettings {
        self.settings.get()
    }

    /// The receiver: a new sighting (if any) and the tracker's counters.
    /// A sighting the frame task has not taken yet is replaced, and
    /// counted as dropped.
    pub fn publish(&self, sighting: Option<Sighting>, counters: Counters) {
        self.publish_after(sighting, 0, counters);
    }

    /// [`publish`](Self::publish) of the last of several sightings that
    /// came at once, `older` of them before it (never seen by the frame
    /// task: counted as dropped).
    pub fn publish_after(&self, sighting: Option<Sighting>, older: u32, counters: Counters) {
        self.received.update(|r| {
            let dropped = r.counters.dropped.wrapping_add(older);
            if let Some(s) = sighting {
                let replaced = !r.taken;
                r.sighting = s;
                r.seq = r.seq.wrapping_add(1);
                if s.count() > 0 {
                    r.seen = r.seen.wrapping_add(1);
                }
                r.taken = false;
                r.counters = counters;
                r.counters.dropped = dropped.wrapping_add(u32::from(replaced));
            } else {
                r.counters = counters;
                r.counters.dropped = dropped;
            }
        });
    }

    /// The frame task: the sighting published since the last call, if
    /// any.
    pub fn take(&self) -> Option<Sighting> {
        self.received.update(|r| {
            if r.taken {
                return None;
            }
            r.taken = true;
            Some(r.sighting)
        })
    }

    /// The console and the input task: what was received so far.
    pub fn received(&self) -> Received {
        self.received.get()
    }

    /// The input task: sightings with somebody in them so far, while the
    /// radar counts as presence (`None`: off).
    pub fn presence(&self) -> Option<u32> {
        if self.settings().radar {
            Some(self.received().seen)
        } else {
            None
        }
    }
}

impl Default for TrackLink {
    fn default() -> Self {
        Self::new()
    }
}

impl core::fmt::Debug for TrackLink {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("TrackLink")
            .field("settings", &self.settings())
            .field("received", &self.received())
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::Person;
    use crate::units::Millimetres;

    #[test]
    fn an_untaken_sighting_replaced_is_counted_dropped() {
        let link = TrackLink::new();
        assert_eq!(link.take(), None);
        let mut one = Sighting::NOBODY;
        one.people[0] = Some(Person {
            x: Millimetres(0),
            y: Millimetres(1000),
        });
        let c = Counters {
            good: 1,
            ..Counters::default()
        };
        link.publish(Some(one), c);
        link.publish(Some(Sighting::NOBODY), c);
        assert_eq!(link.received().counters.dropped, 1);
        assert_eq!(link.take(), Some(Sighting::NOBODY));
        assert_eq!(link.take(), None);
        link.publish(None, c);
        assert_eq!(link.received().counters.dropped, 1);
        assert_eq!(link.received().seen, 1);
        assert_eq!(link.presence(), None, "off by default");
    }
}
