//! The join between two loops: its length, the blend weight, and the
//! timing a stream of loops follows (in µs: the same at any frame rate).

use crate::playback::Playback;
use crate::units::Millis;

/// How long an outgoing loop is blended into the incoming one: 2 s (60
/// samples of a 900-sample, 30 s loop; 100 frames at 50 Hz).
pub const JOIN: Millis = Millis(2000);

/// Largest join in samples the generator keeps an exit segment for.
pub const MAX_JOIN_SAMPLES: usize = 64;

/// Why a playback cannot carry a stream of loops.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum IdleError {
    /// The loop is shorter than four joins ([`JOIN`] each).
    LoopTooShort,
    /// The join covers fewer than 2 or more than [`MAX_JOIN_SAMPLES`]
    /// samples of the loop.
    JoinSamples,
}

impl IdleError {
    /// What went wrong, for a person.
    #[must_use]
    pub const fn message(self) -> &'static str {
        match self {
            Self::LoopTooShort => "the loop must last at least four joins (8 s)",
            Self::JoinSamples => {
                "a join (2 s) must cover 2 to 64 samples of the loop: change N or the loop duration"
            }
        }
    }
}

/// How a stream of loops is laid out in time and samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct IdleTiming {
    /// The playback of one loop.
    pub playback: Playback,
    /// A loop's duration, µs (`L`).
    pub loop_us: u64,
    /// A join's duration, µs ([`JOIN`], `J`).
    pub join_us: u64,
    /// Samples of a loop the join covers: `J·N/L`, rounded down.
    pub join_samples: usize,
}

impl IdleTiming {
    /// The timing of loops played by `playback`.
    ///
    /// # Errors
    /// An [`IdleError`] if the loop is shorter than four joins, or its join
    /// covers too few or too many samples.
    pub const fn new(playback: Playback) -> Result<Self, IdleError> {
        let loop_us = playback.loop_duration().0 as u64 * 1000;
        let join_us = JOIN.0 as u64 * 1000;
        if loop_us < 4 * join_us {
            return Err(IdleError::LoopTooShort);
        }
        let join_samples = (join_us * playback.samples() as u64 / loop_us) as usize;
        if join_samples < 2 || join_samples > MAX_JOIN_SAMPLES {
            return Err(IdleError::JoinSamples);
        }
        Ok(Self {
            playback,
            loop_us,
            join_us,
            join_samples,
        })
    }

    /// How long a set still reads its join: until no spline window reaches
    /// back before the join's last sample `J` (the window of a frame starts
    /// one sample before it), the first time `t` with `t·N/L ≥ J + 1`, µs.
    #[must_use]
    pub const fn join_read_us(&self) -> u64 {
        let n = self.playback.samples() as u64;
        let need = (self.join_samples as u64 + 1) * self.loop_us;
        need.div_ceil(n)
    }

    /// Time from one join's start to the next: `L − J` (each loop's
    /// first `J` are its join in, its last `J` its join out), µs.
    #[must_use]
    pub const fn period_us(&self) -> u64 {
        self.loop_us - self.join_us
    }
}

/// Fraction bits of the blend weight.
const W_BITS: u32 = 15;

/// The blend weight of join sample `i` of `n` in Q15 (32 768 = all
/// incoming): the smootherstep s(u) = 10u³ − 15u⁴ + 6u⁵ of u = i/n,
/// rounded: 0 at `i = 0`, 32 768 at `i = n` and after, with zero first and
/// second derivatives at both ends.
#[must_use]
pub const fn join_weight(i: usize, n: usize) -> u16 {
    if n == 0 || i >= n {
        return 1 << W_BITS;
    }
    let (i, n) = (i as u128, n as u128);
    // s = i³(10n² − 15in + 6i²)/n⁵, exact in u128.
    let num = i * i * i * (10 * n * n + 6 * i * i - 15 * i * n);
    let den = n * n * n * n * n;
    ((num * (1 << W_BITS) + den / 2) / den) as u16
}

/// `from` moved towards `to` by `weight` (Q15): a convex combination, so
/// it lies between the two.
pub(super) const fn blend(from: i32, to: i32, weight: u16) -> i32 {
    let step = ((to as i64 - from as i64) * weight as i64 + (1 << (W_BITS - 1))) >> W_BITS;
    (from as i64 + step) as i32
}
