//! Loop time to samples: the [`LoopSource`] a player reads, the
//! [`Playback`] timing (frame period, loop duration) and the interpolation
//! window and weights the [`Player`](super::Player) uses.

use core::num::{NonZeroU64, NonZeroUsize};

use crate::units::{Angle, Microseconds, Millis, Timestamp};

/// A looping sequence of angles (one axis' trajectory).
pub trait LoopSource {
    /// Number of samples in one loop.
    fn len(&self) -> usize;

    /// Sample `index` (wrapping modulo [`len`](Self::len); an empty loop reads 0).
    fn angle(&self, index: usize) -> Angle;

    /// Whether the loop has no samples.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl LoopSource for [Angle] {
    fn len(&self) -> usize {
        <[Angle]>::len(self)
    }

    fn angle(&self, index: usize) -> Angle {
        match <[Angle]>::len(self) {
            0 => Angle::ZERO,
            n => self.get(index % n).copied().unwrap_or(Angle::ZERO),
        }
    }
}

impl<const N: usize> LoopSource for [Angle; N] {
    fn len(&self) -> usize {
        N
    }

    fn angle(&self, index: usize) -> Angle {
        self.as_slice().angle(index)
    }
}

/// Bad playback parameters, rejected by [`Playback::new`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PlaybackError {
    /// The loop duration is zero.
    ZeroLoopDuration,
    /// The frame period is zero.
    ZeroFramePeriod,
    /// The loop has no samples.
    NoSamples,
    /// The loop has more than `u32::MAX` samples.
    TooManySamples,
}

/// Fraction bits of [`Playback::position`] (Q16, 1.0 = 65 536).
const FRAC_BITS: u32 = 16;

/// Maps frame indices to loop positions and interpolated offsets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Playback {
    /// Loop duration in µs (≤ 2^32 · 1000 < 2^42).
    pub(super) loop_us: NonZeroU64,
    /// Frame period in µs (≥ 1).
    pub(super) frame_us: u32,
    /// Samples per loop.
    pub(super) samples: NonZeroUsize,
}

impl Playback {
    /// Playback of a loop of `samples` samples lasting `loop_duration`, one frame
    /// every `frame_period`.
    ///
    /// All loops given to [`offsets`](Self::offsets) should have `samples`
    /// samples; a loop of another length is read modulo its own length.
    ///
    /// # Errors
    /// [`PlaybackError::ZeroLoopDuration`], [`PlaybackError::ZeroFramePeriod`] or
    /// [`PlaybackError::NoSamples`] if the respective parameter is zero,
    /// [`PlaybackError::TooManySamples`] above `u32::MAX` samples.
    pub const fn new(
        loop_duration: Millis,
        frame_period: Microseconds,
        samples: usize,
    ) -> Result<Self, PlaybackError> {
        let Some(loop_us) = NonZeroU64::new(loop_duration.0 as u64 * 1000) else {
            return Err(PlaybackError::ZeroLoopDuration);
        };
        if frame_period.0 == 0 {
            return Err(PlaybackError::ZeroFramePeriod);
        }
        let Some(samples) = NonZeroUsize::new(samples) else {
            return Err(PlaybackError::NoSamples);
        };
        if samples.get() as u64 > u32::MAX as u64 {
            return Err(PlaybackError::TooManySamples);
        }
        Ok(Self {
            loop_us,
            frame_us: frame_period.0,
            samples,
        })
    }

    /// The loop duration.
    #[must_use]
    pub const fn loop_duration(&self) -> Millis {
        Millis((self.loop_us.get() / 1000) as u32)
    }

    /// The frame period.
    #[must_use]
    pub const fn frame_period(&self) -> Microseconds {
        Microseconds(self.frame_us)
    }

    /// Samples per loop.
    #[must_use]
    pub const fn samples(&self) -> usize {
        self.samples.get()
    }

    /// Position of frame `frame` in the loop: the sample index at or before it
    /// and the fraction towards the next sample in Q16 (`0..65 536`).
    ///
    /// Exact: time in the loop is `frame · frame_period mod loop_duration`, in µs.
    #[must_use]
    pub const fn position(&self, frame: u64) -> (usize, u32) {
        let pos = self.locate(frame, FRAC_BITS).0;
        let index = (pos >> FRAC_BITS) as usize; // < samples
        let frac = (pos & ((1 << FRAC_BITS) - 1)) as u32;
        (index, frac)
    }

    /// The loop's position at time `at` (µs from its start, any number of
    /// loops on): the sample index at or before it and the fraction towards
    /// the next sample in Q16 (`0..65 536`). Exact.
    #[must_use]
    pub const fn position_at(&self, at: Timestamp) -> (usize, u32) {
        let pos = self.locate_at(at.0, FRAC_BITS).0;
        let index = (pos >> FRAC_BITS) as usize; // < samples
        let frac = (pos & ((1 << FRAC_BITS) - 1)) as u32;
        (index, frac)
    }

    /// `X = t·n·2^bits` for frame `frame` (`t`: its time in the loop, µs):
    /// `(⌊X/L⌋, X mod L)`, exactly. `bits ≤ 16`.
    pub(crate) const fn locate(&self, frame: u64, bits: u32) -> (u64, u64) {
        let l = self.loop_us.get();
        let Some(a) = frame.checked_rem(l) else {
            return (0, 0);
        };
        // t = (frame mod L)·F mod L.
        let t = mul_div_rem(a, self.frame_us as u64, l).1;
        // n < 2³², so n·2^bits < 2⁴⁸.
        mul_div_rem(t, (self.samples.get() as u64) << bits, l)
    }

    /// As [`locate`](Self::locate), for the time `at` µs from the loop's
    /// start.
    pub(crate) const fn locate_at(&self, at: u64, bits: u32) -> (u64, u64) {
        let l = self.loop_us.get();
        let Some(t) = at.checked_rem(l) else {
            return (0, 0);
        };
        mul_div_rem(t, (self.samples.get() as u64) << bits, l)
    }

    /// This playback with frames `period` apart.
    #[must_use]
    pub const fn with_frame_period(mut self, period: Microseconds) -> Self {
        if period.0 != 0 {
            self.frame_us = period.0;
        }
        self
    }

    /// The three offsets (pitch, roll, yaw) of frame `frame`, interpolated
    /// between samples with a cyclic Catmull-Rom spline. [`Player`](super::Player) gives
    /// the same values frame by frame at a fraction of the cost.
    #[must_use]
    pub fn offsets<L: LoopSource + ?Sized>(&self, frame: u64, loops: [&L; 3]) -> [Angle; 3] {
        self.offsets_of(self.position(frame), loops)
    }

    /// The three offsets at time `at` (µs from the loop's start), as
    /// [`offsets`](Self::offsets) gives them for a frame.
    #[must_use]
    pub fn offsets_at<L: LoopSource + ?Sized>(&self, at: Timestamp, loops: [&L; 3]) -> [Angle; 3] {
        self.offsets_of(self.position_at(at), loops)
    }

    fn offsets_of<L: LoopSource + ?Sized>(
        &self,
        (index, frac): (usize, u32),
        loops: [&L; 3],
    ) -> [Angle; 3] {
        let t = frac >> (FRAC_BITS - T_BITS);
        let n = self.samples.get();
        loops.map(|l| {
            let window = Window::load(l, n, index);
            Angle::from_millidegrees(window.at(t))
        })
    }
}

/// Fraction bits of the spline parameter `t` (Q12).
pub(crate) const T_BITS: u32 = 12;

/// Largest difference of neighbouring samples for the 32-bit spline.
const NARROW_STEP: u32 = 1 << 15;

/// The four samples `p₀..p₃` around a spline segment (from `p₁` to `p₂`),
/// and up to two after them read ahead (see [`Player`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Window {
    p: [i32; 4],
    ahead: [i32; 2],
}

impl Window {
    /// No samples (all zero).
    pub(crate) const EMPTY: Self = Self {
        p: [0; 4],
        ahead: [0; 2],
    };

    /// The samples `i − 1 ..= i + 2` of `source` (wrapping at `n`; `i < n`).
    pub(crate) fn load<L: LoopSource + ?Sized>(source: &L, n: usize, i: usize) -> Self {
        let at = |k: usize| source.angle(k).millidegrees();
        let before = if i == 0 { n - 1 } else { i - 1 };
        Self {
            p: [at(before), at(i), at(wrap(i + 1, n)), at(wrap(i + 2, n))],
            ahead: [0; 2],
        }
    }

    /// The window of sample `i` (wrapping at `n`) around its sample `p₁`,
    /// read from `source` but for `p₁`, which the window holds.
    pub(crate) fn complete<L: LoopSource + ?Sized>(&mut self, source: &L, n: usize, i: usize) {
        let at = |k: usize| source.angle(k).millidegrees();
        let before = if i == 0 { n - 1 } else { i - 1 };
        self.p = [
            at(before),
            self.p[1],
            at(wrap(i + 1, n)),
            at(wrap(i + 2, n)),
        ];
        self.ahead = [0; 2];
    }

    /// A window of one sample: its value at `t = 0` is that sample.
    pub(crate) const fn flat(p1: i32) -> Self {
        Self {
            p: [p1; 4],
            ahead: [0; 2],
        }
    }

    /// Moves the window on by one sample, `next` being the new last one.
    #[inline]
    pub(crate) fn shift(&mut self, next: i32) {
        let [_, p1, p2, p3] = self.p;
        self.p = [p1, p2, p3, next];
    }

    /// Moves the window on by one sample read ahead.
    #[inline]
    pub(crate) fn shift_ahead(&mut self) {
        let [next, later] = self.ahead;
        self.shift(next);
        self.ahead = [later, later];
    }

    /// Keeps `sample` as the read-ahead sample `k` (0 or 1).
    #[inline]
    pub(crate) fn set_ahead(&mut self, k: u8, sample: i32) {
        if let Some(slot) = self.ahead.get_mut(usize::from(k)) {
            *slot = sample;
        }
    }

    /// The segment's value at `t` (Q12, `0..4096`), in m°.
    #[inline]
    pub(crate) fn at(&self, t: u32) -> i32 {
        self.at_weights(&Weights::at(t))
    }

    /// The segment's value at the `t` of `w`, in m° (see the module docs).
    ///
    /// The 32-bit form applies when `|p₁| < 2²⁹` and each difference lies in
    /// `[−2¹⁵, 2¹⁵)`: then every sample is within 2³⁰, so the wrapping
    /// differences are the true ones. (Each condition is a biased value
    /// below 2¹⁶, so one comparison of their bitwise or tests them all.)
    #[inline]
    pub(crate) fn at_weights(&self, w: &Weights) -> i32 {
        let [p0, p1, p2, p3] = self.p;
        let (d0, d1, d2) = (
            p1.wrapping_sub(p0),
            p2.wrapping_sub(p1),
            p3.wrapping_sub(p2),
        );
        let bias = |d: i32| (d as u32).wrapping_add(NARROW_STEP);
        let range = (p1 as u32).wrapping_add(1 << 29) >> 14;
        if range | bias(d0) | bias(d1) | bias(d2) < 2 * NARROW_STEP {
            let [w0, w1, w2] = w.0;
            let twice = (w0 * d0 + w1 * d1 + w2 * d2) >> T_BITS;
            return p1 + ((twice + 1) >> 1);
        }
        self.at_wide(w)
    }

    /// [`at_weights`](Self::at_weights) in `i64`, for any samples.
    #[inline(never)]
    fn at_wide(&self, w: &Weights) -> i32 {
        let [p0, p1, p2, p3] = self.p.map(i64::from);
        let [w0, w1, w2] = w.0.map(i64::from);
        let twice = (w0 * (p1 - p0) + w1 * (p2 - p1) + w2 * (p3 - p2)) >> T_BITS;
        let value = p1 + ((twice + 1) >> 1);
        value.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
    }
}

/// The spline weights `[w₀, w₁, w₂]` at one `t`, Q12 (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Weights([i32; 3]);

impl Weights {
    /// The weights at `t` (Q12, `0..4096`).
    #[inline]
    pub(crate) const fn at(t: u32) -> Self {
        let t = (t & ((1 << T_BITS) - 1)) as i32;
        let t2 = (t * t) >> T_BITS;
        let t3 = (t2 * t) >> T_BITS;
        Self([t - 2 * t2 + t3, t + 3 * t2 - 2 * t3, t3 - t2])
    }
}

/// `(⌊t·m/l⌋, t·m mod l)` for `t < l < 2⁴⁷` and any `m`, in `u64`: long
/// multiplication by the 16-bit digits of `m` from the top, reducing modulo
/// `l` after each (`r·2¹⁶ + t·digit < 2⁶³ + 2⁶³`). The quotient is below `m`.
pub(crate) const fn mul_div_rem(t: u64, m: u64, l: u64) -> (u64, u64) {
    let (mut quotient, mut rem) = (0u64, 0u64);
    // From the highest non-zero digit.
    let mut shift = (64 - m.leading_zeros()).div_ceil(16) * 16;
    while shift > 0 {
        shift -= 16;
        let partial = (rem << 16) + t * ((m >> shift) & 0xFFFF);
        let (Some(digit), Some(rest)) = (partial.checked_div(l), partial.checked_rem(l)) else {
            return (0, 0);
        };
        quotient = (quotient << 16) + digit;
        rem = rest;
    }
    (quotient, rem)
}

/// `k` modulo `n` for `k < 3n`, by subtraction.
pub(crate) fn wrap(mut k: usize, n: usize) -> usize {
    while k >= n && n > 0 {
        k -= n;
    }
    k
}
