//! A level that becomes an edge once it has held for the debounce time.
//!
//! The debouncer is told the input's level whenever the source says it
//! may have changed, and at the deadline it asks for: a new level is a
//! candidate from the moment it is seen, and becomes the debounced level
//! (an edge) when it is seen again `hold` or more later without having
//! changed in between. A level that changes back before then was chatter:
//! no edge. The first level it is told is taken as it is, without an edge
//! (see the [module docs](super#chatter-stuck-inputs-two-sensors-at-once)).

use super::Micros;

/// One input's debouncer; see the [module docs](self). Its debounce time
/// is its input's role's, given with each call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Debouncer {
    /// The debounced level (`true`: high).
    stable: bool,
    /// The level last seen, and since when.
    candidate: bool,
    since: Micros,
    /// Whether a level was seen yet.
    primed: bool,
}

impl Default for Debouncer {
    fn default() -> Self {
        Self::new()
    }
}

impl Debouncer {
    /// A debouncer that has seen nothing: its first level is taken as it is.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            stable: false,
            candidate: false,
            since: Micros(0),
            primed: false,
        }
    }

    /// The debounced level (`true`: high).
    #[must_use]
    pub const fn level(&self) -> bool {
        self.stable
    }

    /// The level `level` seen at `now`, with a debounce time of `hold` µs:
    /// `Some(new level)` when it makes an edge.
    pub fn update(&mut self, now: Micros, level: bool, hold: u64) -> Option<bool> {
        if !self.primed {
            self.primed = true;
            (self.stable, self.candidate, self.since) = (level, level, now);
            return None;
        }
        if level != self.candidate {
            self.candidate = level;
            self.since = now;
        }
        if self.candidate != self.stable && now.0.saturating_sub(self.since.0) >= hold {
            self.stable = self.candidate;
            return Some(self.stable);
        }
        None
    }

    /// When to look again for an edge (with a debounce time of `hold` µs),
    /// if one may come without another change of level.
    #[must_use]
    pub const fn deadline(&self, hold: u64) -> Option<Micros> {
        if self.primed && self.candidate != self.stable {
            Some(Micros(self.since.0.saturating_add(hold)))
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1000;

    /// Edges out of `levels` (`(ms, level)`), each seen at its time and at
    /// every deadline asked for, as the input task does.
    fn edges(hold_ms: u64, levels: &[(u64, bool)]) -> Vec<(u64, bool)> {
        let hold = hold_ms * MS;
        let mut d = Debouncer::new();
        let mut out = Vec::new();
        let mut level = false;
        let seen = |d: &mut Debouncer, at: u64, level: bool, out: &mut Vec<(u64, bool)>| {
            if let Some(edge) = d.update(Micros(at), level, hold) {
                out.push((at / MS, edge));
            }
        };
        for (i, &(at, new)) in levels.iter().enumerate() {
            let at = at * MS;
            // The deadlines before this change.
            while let Some(due) = d.deadline(hold).filter(|due| due.0 <= at) {
                seen(&mut d, due.0, level, &mut out);
                if d.deadline(hold) == Some(due) {
                    break;
                }
            }
            level = new;
            seen(&mut d, at, level, &mut out);
            if i + 1 == levels.len()
                && let Some(due) = d.deadline(hold)
            {
                seen(&mut d, due.0, level, &mut out);
            }
        }
        out
    }

    #[test]
    fn a_level_held_for_the_debounce_time_is_an_edge() {
        assert_eq!(
            edges(5, &[(0, true), (100, false), (110, true)]),
            [(105, false), (115, true)]
        );
    }

    #[test]
    fn the_first_level_is_no_edge() {
        assert_eq!(edges(5, &[(0, false)]), []);
        assert_eq!(edges(5, &[(0, true)]), []);
        let mut d = Debouncer::new();
        assert_eq!(d.deadline(5 * MS), None);
        assert_eq!(d.update(Micros(7), true, 5 * MS), None);
        assert!(d.level());
    }

    #[test]
    fn chatter_shorter_than_the_debounce_time_is_no_edge() {
        // Bounces every 2 ms for 20 ms, then back where it was.
        let mut levels = vec![(0, true)];
        levels.extend((0..10).map(|k| (100 + 2 * k, k % 2 == 0)));
        levels.push((120, true));
        assert_eq!(edges(5, &levels), []);
        // The same bouncing, then held low: one edge, 5 ms after the last
        // bounce (low at 118 ms).
        let mut levels = vec![(0, true)];
        levels.extend((0..10).map(|k| (100 + 2 * k, k % 2 == 0)));
        levels.push((120, false));
        assert_eq!(edges(5, &levels), [(123, false)]);
    }

    #[test]
    fn a_level_stuck_forever_is_one_edge() {
        assert_eq!(edges(50, &[(0, false), (10, true)]), [(60, true)]);
        let hold = 50 * MS;
        let mut d = Debouncer::new();
        d.update(Micros(0), false, hold);
        d.update(Micros(10 * MS), true, hold);
        assert_eq!(d.update(Micros(60 * MS), true, hold), Some(true));
        for t in 61..10_000 {
            assert_eq!(d.update(Micros(t * MS), true, hold), None);
        }
        assert_eq!(d.deadline(hold), None);
    }
}
