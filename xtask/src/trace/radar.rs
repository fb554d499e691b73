//! The radar in the trace: a script's radar lines as the LD2450's frames,
//! frame `k` due at `k` · 100 ms with the last line's people by then, on
//! the schedule `sim/radar.mjs` keeps in the emulator.

use idle_head_core::Millimetres;
use idle_head_core::behaviour::ShowLink;
use idle_head_core::track::{Counters, Person, Sighting};

use super::{Event, Kind};

/// The radar's frame period, µs (the LD2450 reports ten times a second).
pub const PERIOD_US: u64 = 100_000;

/// A script's radar lines (when each sees whom, in time order), and the
/// next frame to send.
pub struct Radar {
    lines: Vec<(u64, Sighting)>,
    next: u64,
}

impl Radar {
    pub fn of(events: &[Event]) -> Self {
        let person = |(x, y)| Person {
            x: Millimetres(x),
            y: Millimetres(y),
        };
        let radar = |e: &Event| match e.kind {
            Kind::Radar(seen) => {
                let people = seen.map(|p| p.map(person));
                Some((e.at_us, Sighting { people }))
            }
            _ => None,
        };
        let lines: Vec<(u64, Sighting)> = events.iter().filter_map(radar).collect();
        let next = lines.first().map_or(u64::MAX, |l| l.0.div_ceil(PERIOD_US));
        Self { lines, next }
    }

    /// Publishes the frames due by `t_us` (the frame about to be played) to
    /// `show`'s track link, as the receiver does.
    pub fn send(&mut self, show: &ShowLink, t_us: u64) {
        while self.next.saturating_mul(PERIOD_US) <= t_us {
            let due = self.next * PERIOD_US;
            let seen = self.lines.iter().take_while(|l| l.0 <= due).last();
            let seen = seen.map_or(Sighting::NOBODY, |l| l.1);
            self.next += 1;
            let counters = Counters {
                good: u32::try_from(self.next).unwrap_or(u32::MAX),
                ..Counters::default()
            };
            show.track.publish(Some(seen), counters);
        }
    }
}
