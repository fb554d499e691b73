//! A rig whose radar sees scripted people: sightings at the radar's 10 Hz,
//! handed to the head between frames as the frame task does.

use idle_head_core::track::{PEOPLE, Person, Sighting, TrackSettings};
use idle_head_core::{Millimetres, Timestamp};

use crate::rig::Rig;

/// The radar's frame period, µs.
pub const RADAR_US: u64 = 100_000;

/// People at `(x, y)` mm in the radar's frame.
#[must_use]
pub fn sighting(people: &[(i32, i32)]) -> Sighting {
    let mut s = Sighting::NOBODY;
    for (slot, &(x, y)) in s.people.iter_mut().zip(people.iter().take(PEOPLE)) {
        *slot = Some(Person {
            x: Millimetres(x),
            y: Millimetres(y),
        });
    }
    s
}

/// The built-in track settings with the radar on.
#[must_use]
pub fn radar_on() -> TrackSettings {
    TrackSettings {
        radar: true,
        ..TrackSettings::DEFAULT
    }
}

impl Rig {
    /// Plays `frames` frames with `settings`; before each frame whose time
    /// reaches the radar's next frame, `people` at that time (µs since
    /// frame 0) is handed over as a sighting.
    pub fn run_tracked(
        &mut self,
        frames: u64,
        settings: &TrackSettings,
        mut people: impl FnMut(u64) -> Sighting,
    ) {
        for _ in 0..frames {
            let frame_us = u64::from(self.period);
            let now = self.at;
            // The radar's frames fall between the head's: each is handed
            // over before the first head frame at or after it.
            let due = now.div_ceil(RADAR_US) * RADAR_US;
            let sighting = (due < now + frame_us).then(|| people(due));
            self.head.track(
                &mut self.driver,
                Timestamp(now),
                settings,
                sighting.as_ref(),
            );
            self.run(1);
        }
    }

    /// The time of frame `k`, µs.
    #[must_use]
    pub fn time_us(&self, k: usize) -> u64 {
        k as u64 * u64::from(self.head.mixer().params().frame_us())
    }
}
