//! Attention: whom the head looks at, and when it glances elsewhere.
//!
//! Fed with each sighting (up to three people, [`crate::track`]) and
//! asked again at the deadlines it gives, it keeps a short track of each
//! person (where, since when, last seen) and says where the gaze should
//! be: at a person, away from them for a moment, or nowhere (nobody
//! there). Times are µs of the frame task's clock; nothing here counts
//! frames. The timings and their sources are in the design notes
//! (`docs/design/attention.md`).
//!
//! - **Whom.** A person counts once seen in two sightings (a radar's
//!   single-frame ghost does not turn the head). With `prefer nearest`
//!   the head attends to the nearest; another person takes over only once
//!   nearer by [`MARGIN_MM`] (or an eighth of the distance, if more) for
//!   [`SWITCH`]: two people side by side never make it flick. With
//!   `prefer newest` the latest arrival takes over once counted.
//! - **Glances.** After a dwell of [`DWELL`] on a person the head may
//!   glance at another person, or away and back, for [`GLANCE`]; then it
//!   dwells again.
//! - **Lost.** A person not seen for [`LOST`] is gone: the head holds
//!   where it looked meanwhile, then turns to someone else, or, with
//!   nobody left, the tracker returns the gaze to the centre.

use crate::track::{PEOPLE, Person, Prefer, Sighting};

use crate::track::geometry::distance;

/// How long a person may go unseen before they count as gone, µs.
pub const LOST: u64 = 1_500_000;
/// How long a nearer person must stay nearer to take over, µs.
pub const SWITCH: u64 = 1_000_000;
/// How much nearer, mm, at the least.
pub const MARGIN_MM: u32 = 300;
/// A dwell on a person before a glance may come: 2.6 s to 4.0 s, µs.
pub const DWELL: (u64, u64) = (2_600_000, 4_000_000);
/// A glance at another person or away, held this long once there, µs.
pub const GLANCE: (u64, u64) = (700_000, 1_300_000);
/// How far an aversion turns from the person, m°.
pub const AVERT_MDEG: i32 = 12_000;
/// How far two sightings apart may put one person: this much, mm, plus
/// [`GATE_PER_MS`] for each ms since they were last seen, up to
/// [`GATE_MAX_MM`].
pub const GATE_MM: u32 = 600;
const GATE_PER_MS: u32 = 1;
const GATE_MAX_MM: u32 = 2000;

/// One person as attention follows them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Track {
    pub(crate) at: Person,
    /// When first and last seen, µs.
    first: u64,
    last: u64,
    /// Sightings they were in (saturating).
    seen: u8,
}

impl Track {
    fn counted(&self) -> bool {
        self.seen >= 2
    }
}

/// Where the gaze should be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Aim {
    /// Nobody there (or nobody counted yet).
    Nobody,
    /// At the person of this track.
    Person(usize),
    /// Away from the person of this track, by this yaw offset (m°).
    Away(usize, i32),
}

/// What happens now; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Looking at the attended person; a glance may come at this time.
    Dwell(u64),
    /// Glancing (at `aim`) until this time.
    Glance(Aim, u64),
}

/// The attention's state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Attention {
    tracks: [Option<Track>; PEOPLE],
    attended: Option<usize>,
    phase: Phase,
    /// Since when a nearer person has been nearer (`prefer nearest`).
    rival: Option<(usize, u64)>,
    /// xorshift32 for the timings.
    rng: u32,
}

impl Attention {
    pub(crate) const fn new(seed: u32) -> Self {
        Self {
            tracks: [None; PEOPLE],
            attended: None,
            phase: Phase::Dwell(0),
            rival: None,
            rng: seed | 1,
        }
    }

    /// The person of track `i`.
    pub(crate) fn person(&self, i: usize) -> Option<Person> {
        self.tracks.get(i).copied().flatten().map(|t| t.at)
    }

    /// Whom the head attends to, if anyone.
    pub(crate) const fn attended(&self) -> Option<usize> {
        self.attended
    }

    /// Whether track `i` was in the sighting at `now`.
    pub(crate) fn fresh(&self, i: usize, now: u64) -> bool {
        self.tracks
            .get(i)
            .copied()
            .flatten()
            .is_some_and(|t| t.last == now)
    }

    /// Where the gaze should be now.
    pub(crate) fn aim(&self) -> Aim {
        match (self.attended, self.phase) {
            (None, _) => Aim::Nobody,
            (Some(_), Phase::Glance(aim, _)) => aim,
            (Some(i), Phase::Dwell(_)) => Aim::Person(i),
        }
    }

    /// A uniform draw in `range`, µs.
    fn draw(&mut self, (lo, hi): (u64, u64)) -> u64 {
        let mut x = self.rng;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.rng = x;
        // A 32-bit multiply-shift: no division.
        let span = hi.saturating_sub(lo).min(u64::from(u32::MAX)) as u32;
        lo + ((u64::from(x) * u64::from(span)) >> 32)
    }

    /// A sighting at `now`: the people matched to the tracks (new ones
    /// start), then [`tick`](Self::tick).
    pub(crate) fn sight(&mut self, now: u64, sighting: &Sighting, prefer: Prefer) {
        let mut used = [false; PEOPLE];
        for person in sighting.people.iter().flatten() {
            if person.y.0 <= 0 {
                // Behind or at the sensor: not a person.
                continue;
            }
            // The nearest free track within its gate.
            let mut best: Option<(usize, u32)> = None;
            for (i, track) in self.tracks.iter().enumerate() {
                let (Some(t), Some(false)) = (track, used.get(i)) else {
                    continue;
                };
                let since_ms = (now.saturating_sub(t.last) / 1000).min(u64::from(u32::MAX)) as u32;
                let gate = GATE_MM
                    .saturating_add(since_ms.saturating_mul(GATE_PER_MS))
                    .min(GATE_MAX_MM);
                let d = apart(t.at, *person);
                if d <= gate && best.is_none_or(|(_, b)| d < b) {
                    best = Some((i, d));
                }
            }
            let slot = match best {
                Some((i, _)) => Some(i),
                None => self.tracks.iter().position(Option::is_none),
            };
            let Some(i) = slot else { continue };
            if let (Some(track), Some(u)) = (self.tracks.get_mut(i), used.get_mut(i)) {
                *u = true;
                *track = Some(match *track {
                    Some(t) if best.is_some() => Track {
                        at: *person,
                        last: now,
                        seen: t.seen.saturating_add(1),
                        ..t
                    },
                    _ => Track {
                        at: *person,
                        first: now,
                        last: now,
                        seen: 1,
                    },
                });
            }
        }
        self.tick(now, prefer);
    }

    /// At `now`: the people gone dropped, whom to attend to, the glances
    /// begun and ended.
    pub(crate) fn tick(&mut self, now: u64, prefer: Prefer) {
        for track in &mut self.tracks {
            if track.is_some_and(|t| now.saturating_sub(t.last) >= LOST) {
                *track = None;
            }
        }
        let present = |i: usize| self.tracks.get(i).copied().flatten().is_some();
        if let Phase::Glance(Aim::Person(i) | Aim::Away(i, _), _) = self.phase
            && !present(i)
        {
            self.phase = Phase::Dwell(now);
        }
        if self.attended.is_some_and(|i| !present(i)) {
            self.attended = None;
            self.rival = None;
        }
        let choice = self.choose(now, prefer);
        if choice != self.attended {
            self.attended = choice;
            self.rival = None;
            let dwell = self.draw(DWELL);
            self.phase = Phase::Dwell(now + dwell);
            return;
        }
        match self.phase {
            Phase::Dwell(until) if now >= until => self.glance(now),
            Phase::Glance(_, until) if now >= until => {
                let dwell = self.draw(DWELL);
                self.phase = Phase::Dwell(now + dwell);
            }
            _ => {}
        }
    }

    /// The next time [`tick`](Self::tick) has something to do without a
    /// sighting, µs.
    pub(crate) fn deadline(&self) -> u64 {
        let mut soonest = match self.phase {
            Phase::Dwell(t) | Phase::Glance(_, t) => t,
        };
        for t in self.tracks.iter().flatten() {
            soonest = soonest.min(t.last.saturating_add(LOST));
        }
        if let Some((_, since)) = self.rival {
            soonest = soonest.min(since.saturating_add(SWITCH));
        }
        soonest
    }

    /// Whom to attend to at `now`.
    fn choose(&mut self, now: u64, prefer: Prefer) -> Option<usize> {
        let counted = |t: &Option<Track>| t.filter(Track::counted);
        let current = self
            .attended
            .filter(|&i| self.tracks.get(i).is_some_and(|t| counted(t).is_some()));
        match prefer {
            Prefer::Newest => {
                let newest = (0..PEOPLE)
                    .filter_map(|i| Some((i, counted(self.tracks.get(i)?)?.first)))
                    .max_by_key(|&(_, first)| first)
                    .map(|(i, _)| i);
                newest.or(current)
            }
            Prefer::Nearest => {
                let dist = |i: usize| {
                    self.tracks
                        .get(i)
                        .copied()
                        .flatten()
                        .filter(Track::counted)
                        .map(|t| distance(&t.at))
                };
                let nearest = (0..PEOPLE)
                    .filter_map(|i| Some((i, dist(i)?)))
                    .min_by_key(|&(_, d)| d);
                let Some(c) = current else {
                    return nearest.map(|(i, _)| i);
                };
                let (Some((n, dn)), Some(dc)) = (nearest, dist(c)) else {
                    return Some(c);
                };
                let margin = MARGIN_MM.max(dc / 8);
                if n == c || dn.saturating_add(margin) > dc {
                    self.rival = None;
                    return Some(c);
                }
                match self.rival {
                    Some((r, since)) if r == n => {
                        if now.saturating_sub(since) >= SWITCH {
                            Some(n)
                        } else {
                            Some(c)
                        }
                    }
                    _ => {
                        self.rival = Some((n, now));
                        Some(c)
                    }
                }
            }
        }
    }

    /// A dwell ended at `now`: with others there, half the time a glance
    /// at one of them, a quarter an aversion; alone, half the time an
    /// aversion; else another dwell.
    fn glance(&mut self, now: u64) {
        let Some(i) = self.attended else { return };
        let other = (0..PEOPLE).find(|&k| {
            k != i
                && self
                    .tracks
                    .get(k)
                    .copied()
                    .flatten()
                    .is_some_and(|t| t.counted())
        });
        let roll = self.draw((0, 4));
        let aim = match (other, roll) {
            (Some(k), 0 | 1) => Some(Aim::Person(k)),
            (Some(_), 2) | (None, 0 | 1) => {
                let side = if self.draw((0, 2)) == 0 { -1 } else { 1 };
                Some(Aim::Away(i, side * AVERT_MDEG))
            }
            _ => None,
        };
        let hold = self.draw(GLANCE);
        self.phase = match aim {
            Some(aim) => Phase::Glance(aim, now + hold),
            None => Phase::Dwell(now + self.draw(DWELL)),
        };
    }
}

/// How far apart two positions are, mm.
fn apart(a: Person, b: Person) -> u32 {
    distance(&Person {
        x: crate::units::Millimetres(a.x.0.saturating_sub(b.x.0)),
        y: crate::units::Millimetres(a.y.0.saturating_sub(b.y.0)),
    })
}
