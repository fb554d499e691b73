//! A level that becomes an edge, by one of two rules ([`Debounce`]):
//!
//! - **Hold** (presence sensors): a new level is a candidate from the moment
//!   it is seen, and becomes the debounced level (an edge) when it is seen
//!   again `hold` or more later without having changed in between. A level
//!   that changes back before then was chatter: no edge.
//! - **Leading** (buttons): a change is an edge at once, and for `hold`
//!   after it the input is not looked at, while its contacts bounce. A level
//!   that differs once that time is over is the next edge. A press counts
//!   the moment the contacts first touch, not a debounce time later.
//!
//! The debouncer is told the input's level whenever the source says it may
//! have changed, and at the deadline it asks for. The first level it is
//! told is taken as it is, without an edge (see the [module
//! docs](super#chatter-stuck-inputs-two-sensors-at-once)).

use super::Micros;

/// How an input's level becomes an edge (see the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Debounce {
    /// A new level counts once it has held this long, in µs.
    Hold(u64),
    /// A change counts at once; the input is not looked at for this long
    /// after it, in µs.
    Leading(u64),
}

/// One input's debouncer; see the [module docs](self). Its rule is its
/// input's role's, given with each call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Debouncer {
    /// The debounced level (`true`: high).
    stable: bool,
    /// The level last seen, and since when (leading: the last edge's time).
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

    /// The level `level` seen at `now`, under `rule`: `Some(new level)`
    /// when it makes an edge.
    pub fn update(&mut self, now: Micros, level: bool, rule: Debounce) -> Option<bool> {
        if !self.primed {
            self.primed = true;
            (self.stable, self.candidate, self.since) = (level, level, now);
            return None;
        }
        match rule {
            Debounce::Hold(hold) => {
                if level != self.candidate {
                    self.candidate = level;
                    self.since = now;
                }
                if self.candidate != self.stable && now.0.saturating_sub(self.since.0) >= hold {
                    self.stable = self.candidate;
                    return Some(self.stable);
                }
            }
            Debounce::Leading(hold) => {
                self.candidate = level;
                if level != self.stable && now.0.saturating_sub(self.since.0) >= hold {
                    self.stable = level;
                    self.since = now;
                    return Some(level);
                }
            }
        }
        None
    }

    /// When to look again for an edge under `rule`, if one may come without
    /// another change of level.
    #[must_use]
    pub const fn deadline(&self, rule: Debounce) -> Option<Micros> {
        let hold = match rule {
            Debounce::Hold(hold) | Debounce::Leading(hold) => hold,
        };
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
        edges_by(Debounce::Hold(hold_ms * MS), levels)
    }

    /// As [`edges`], under `rule`.
    fn edges_by(hold: Debounce, levels: &[(u64, bool)]) -> Vec<(u64, bool)> {
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
        assert_eq!(d.deadline(Debounce::Hold(5 * MS)), None);
        assert_eq!(d.update(Micros(7), true, Debounce::Hold(5 * MS)), None);
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
        let hold = Debounce::Hold(50 * MS);
        let mut d = Debouncer::new();
        d.update(Micros(0), false, hold);
        d.update(Micros(10 * MS), true, hold);
        assert_eq!(d.update(Micros(60 * MS), true, hold), Some(true));
        for t in 61..10_000 {
            assert_eq!(d.update(Micros(t * MS), true, hold), None);
        }
        assert_eq!(d.deadline(hold), None);
    }

    #[test]
    fn a_leading_edge_counts_at_once_and_its_bounces_do_not() {
        let rule = Debounce::Leading(5 * MS);
        // Pressed at 100 ms, bouncing for 4 ms: one edge, at 100 ms.
        let mut levels = vec![(0, true)];
        levels.extend((0..5).map(|k| (100 + k, k % 2 == 1)));
        assert_eq!(edges_by(rule, &levels), [(100, false)]);
        // Released at 300 ms: the next edge, at once.
        levels.push((300, true));
        assert_eq!(edges_by(rule, &levels), [(100, false), (300, true)]);
    }

    #[test]
    fn a_leading_edge_undone_within_its_time_is_seen_when_the_time_is_over() {
        // A tap of 2 ms: the press at once, the release when the 5 ms are
        // over (its deadline).
        let rule = Debounce::Leading(5 * MS);
        assert_eq!(
            edges_by(rule, &[(0, true), (100, false), (102, true)]),
            [(100, false), (105, true)]
        );
    }
}
