//! How fast and how sharply a loop moves, so that consecutive loops of an
//! axis stay comparable: a stretch holding the end of a lively loop and the
//! start of a calm one would otherwise measure the lively part against the
//! calm part's P95 and exceed the smoothness bound, join or no join.
//!
//! Measured on the loop's samples in m° (cyclic), per sample: the P95
//! (nearest-rank, as [`crate::metrics`]) and the maximum of |d1| and of
//! |d2|. The bounds are below the frames' bound of 3 where the samples
//! predict the frames less well (see the module docs of [`super`]).

use crate::motion::{Integral16, Sample, Trajectory};

/// Q8 ratios: 256 is 1.
const ONE: u32 = 256;

/// The largest |d1| of either of two consecutive loops over the other's
/// P95|d1|, Q8: 2.
pub const MAX_SPEED_RATIO: u32 = 512;

/// The largest |d2| of either of two consecutive loops over the other's
/// P95|d2|, Q8: 2.25.
pub const MAX_TURN_RATIO: u32 = 576;

/// The largest |d2| over a join's samples over the P95|d2| of the loop it
/// enters, of the two before and of the one after, Q8: 2.75. Below 3
/// because the frames' |d2| are a few m° per frame², so one m° more is a
/// tenth more: a join at exactly 3 times a P95|d2| of 9 m°/sample²
/// measured 10/3 over 3000 frames.
pub const MAX_JOIN_TURN_RATIO: u32 = 704;

/// Loops an axis may draw for one set: the first, and up to 15 more while
/// the last drawn breaks a bound.
pub const MAX_DRAWS: u8 = 16;

/// The P95 and the maximum of |d1| or |d2| over a loop, m° per sample (or
/// per sample²).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Spread {
    /// P95, nearest-rank.
    pub p95: u16,
    /// Maximum.
    pub max: u16,
}

impl Spread {
    /// The spread of |d1| (`TURN` false) or |d2| (`TURN` true) of a loop
    /// given by its d1 (cyclic): the maximum, then the P95 by histograms
    /// of 64 buckets, each pass narrowing to the bucket that holds it (3
    /// passes for values below 4096, no sorting and no buffer).
    fn of<const TURN: bool>(d1: &[i16]) -> Self {
        const BUCKETS: u32 = 64;
        let n = d1.len();
        let last = d1.last().copied().unwrap_or(0);
        let value = |v: i16, prev: i16| {
            if TURN {
                (i32::from(v) - i32::from(prev)).unsigned_abs()
            } else {
                i32::from(v).unsigned_abs()
            }
        };
        let (mut max, mut prev) = (0, last);
        for &v in d1 {
            max = max.max(value(v, prev));
            prev = v;
        }
        // Nearest rank: the smallest v with at least ⌈0.95·n⌉ values ≤ v.
        let rank = (n * 95).div_ceil(100) as u32;
        // The P95 lies in base..base + width; `below` values lie under base.
        let (mut base, mut width, mut below) = (0u32, max + 1, 0u32);
        let mut shift = 0u32;
        while (width - 1) >> shift >= BUCKETS {
            shift += 1;
        }
        loop {
            let mut counts = [0u32; BUCKETS as usize];
            let mut prev = last;
            for &v in d1 {
                let offset = value(v, prev).wrapping_sub(base);
                prev = v;
                if offset < width {
                    // Below 64 (width ≤ 64 << shift); the mask spares a check.
                    counts[(offset >> shift) as usize & (BUCKETS as usize - 1)] += 1;
                }
            }
            let mut bucket = 0;
            for (k, &c) in counts.iter().enumerate() {
                bucket = k as u32;
                if below + c >= rank {
                    break;
                }
                below += c;
            }
            base += bucket << shift;
            if shift == 0 {
                return Self {
                    p95: base.min(0xFFFF) as u16,
                    max: max.min(0xFFFF) as u16,
                };
            }
            width = width.saturating_sub(bucket << shift).min(1 << shift);
            shift = shift.saturating_sub(6);
        }
    }

    /// The larger of `self.max / other.p95` and `other.max / self.p95`,
    /// Q8, rounded up (`u32::MAX` if a P95 is 0).
    const fn cross(self, other: Self) -> u32 {
        let a = ratio(self.max, other.p95);
        let b = ratio(other.max, self.p95);
        if a > b { a } else { b }
    }
}

/// `max / p95` in Q8, rounded up; `u32::MAX` when `p95` is 0.
const fn ratio(max: u16, p95: u16) -> u32 {
    if p95 == 0 {
        return u32::MAX;
    }
    ((max as u32) << 8).div_ceil(p95 as u32)
}

/// `value` Q8 scaled so that `bound` maps to [`ONE`] (saturating).
const fn against(value: u32, bound: u32) -> u32 {
    if value == u32::MAX || bound == 0 {
        return u32::MAX;
    }
    let scaled = (value as u64 * ONE as u64).div_ceil(bound as u64);
    if scaled > u32::MAX as u64 {
        u32::MAX
    } else {
        scaled as u32
    }
}

/// How a loop moves: the spread of its |d1| (speed) and |d2| (turns).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pace {
    /// |d1|, m° per sample.
    pub speed: Spread,
    /// |d2|, m° per sample².
    pub turn: Spread,
}

impl Pace {
    /// The pace of `angles`, one loop in m° taken cyclically; all zero for
    /// fewer than three samples. Uses `angles` as scratch: it holds d1
    /// afterwards.
    #[must_use]
    pub fn of(angles: &mut [i16]) -> Self {
        let n = angles.len();
        let Some(&first) = angles.first() else {
            return Self::default();
        };
        if n < 3 {
            return Self::default();
        }
        // d1 in place, front to back (sample i + 1 is still unread).
        for i in 0..n {
            let next = angles.get(i + 1).copied().unwrap_or(first);
            if let Some(a) = angles.get_mut(i) {
                *a = (i32::from(next) - i32::from(*a)).clamp(-0x7FFF, 0x7FFF) as i16;
            }
        }
        Self {
            speed: Spread::of::<false>(angles),
            turn: Spread::of::<true>(angles),
        }
    }

    /// The pace of `loop_` (the ring: the same from any start).
    #[must_use]
    pub fn of_loop<const N: usize>(loop_: &Trajectory<Integral16, N>) -> Self {
        // 1.8 KB of stack, freed before the entry search takes its own.
        let scale = loop_.scale();
        let mut angles = [0i16; N];
        for (a, s) in angles.iter_mut().zip(loop_.samples()) {
            // Inside the axis' range, which the configuration keeps within
            // ±32.767° (an i16 of m°).
            *a = scale.angle(s.to_scratch()).millidegrees() as i16;
        }
        Self::of(&mut angles)
    }

    /// How far `self` and the outgoing loop's pace `out` are from keeping
    /// pace, Q8: the largest of the speed and turn ratios
    /// ([`Spread::cross`]), each divided by its bound. At most 256: within
    /// both bounds.
    #[must_use]
    pub const fn score(self, out: Self) -> u32 {
        let speed = against(self.speed.cross(out.speed), MAX_SPEED_RATIO);
        let turn = against(self.turn.cross(out.turn), MAX_TURN_RATIO);
        if speed > turn { speed } else { turn }
    }

    /// Whether a score of [`score`](Self::score) or
    /// [`Paces::score`] is within its bounds.
    #[must_use]
    pub const fn within(score: u32) -> bool {
        score <= ONE
    }
}

/// What an axis' next loop must keep pace with: its last two loops and
/// the join into the last (18 bytes). A stretch of two loop lengths holds
/// two loops whole and the ends of those either side, so each loop is
/// measured against the loops up to two away, and each join against the
/// two loops before it, the one it enters and the one after.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Paces {
    /// The last loop's pace: the loop the next one joins.
    pub last: Pace,
    /// The pace of the loop before it.
    pub before: Pace,
    /// The largest |d2| over the join into the last loop (0: none), m° per
    /// sample².
    pub join_turn: u16,
}

impl Paces {
    /// The history of a stream whose only loop so far has the pace `first`
    /// (set 0, with no join: the loop before it is taken to be itself).
    #[must_use]
    pub const fn new(first: Pace) -> Self {
        Self {
            last: first,
            before: first,
            join_turn: 0,
        }
    }

    /// How far `pace` is from keeping pace with the last two loops
    /// ([`Pace::score`] against each) and from being calm enough for the
    /// join into the last ([`MAX_JOIN_TURN_RATIO`] of its P95|d2|), Q8:
    /// the largest of the three. At most 256: within the bounds.
    #[must_use]
    pub const fn score(self, pace: Pace) -> u32 {
        let last = pace.score(self.last);
        let before = pace.score(self.before);
        let join = against(ratio(self.join_turn, pace.turn.p95), MAX_JOIN_TURN_RATIO);
        max(max(last, before), join)
    }

    /// How far the largest |d2| over the join into `pace`'s loop
    /// (`join_turn`, m° per sample²) is from its bound against the smallest
    /// P95|d2| of that loop and the last two, Q8 (at most 256: within it).
    #[must_use]
    pub const fn join_score(self, pace: Pace, join_turn: u16) -> u32 {
        let p95 = min(min(pace.turn.p95, self.last.turn.p95), self.before.turn.p95);
        against(ratio(join_turn, p95), MAX_JOIN_TURN_RATIO)
    }

    /// Makes `pace` the last loop's, joined with the largest |d2|
    /// `join_turn`.
    pub const fn push(&mut self, pace: Pace, join_turn: u16) {
        self.before = self.last;
        self.last = pace;
        self.join_turn = join_turn;
    }
}

/// The larger of two scores (`u32::max` is not `const`).
const fn max(a: u32, b: u32) -> u32 {
    if a > b { a } else { b }
}

/// The smaller of two P95s.
const fn min(a: u16, b: u16) -> u16 {
    if a < b { a } else { b }
}

/// The largest |d2| of the samples `values` yields, m° per sample².
pub(super) fn max_turn(values: impl Iterator<Item = i32>) -> u16 {
    let (mut a, mut b) = (None::<i32>, None::<i32>);
    let mut max = 0u16;
    for c in values {
        if let (Some(a), Some(b)) = (a, b) {
            max = max.max((c - 2 * b + a).unsigned_abs().min(0xFFFF) as u16);
        }
        (a, b) = (b, Some(c));
    }
    max
}
