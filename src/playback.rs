//! Frame playback: which point of the loop a frame shows.
//!
//! A loop of `N` samples is played over a configurable duration, independent of
//! `N` and of the frame rate. The position of frame `k` is computed from `k`
//! itself (`k · frame_period mod loop_duration`, exact integer arithmetic), so
//! there is no drift however long the head runs. Between samples the loop is
//! interpolated with a cyclic Catmull-Rom spline (cubic Hermite with central
//! difference tangents): continuous in value and velocity everywhere, also
//! across the seam from sample `N − 1` back to sample 0.
//!
//! ```
//! use idle_head::playback::{LoopSource, Playback};
//! use idle_head::{Angle, Microseconds, Millis};
//!
//! let ramp: [Angle; 4] = [0, 1000, 2000, 1000].map(Angle::from_millidegrees);
//! // 4 samples over 160 ms, 20 ms frames: two frames per sample.
//! let p = Playback::new(Millis(160), Microseconds(20_000), 4).unwrap();
//! let at = |k| p.offsets(k, [&ramp, &ramp, &ramp])[0].millidegrees();
//! assert_eq!(at(0), 0);
//! assert_eq!(at(2), 1000); // on sample 1
//! assert_eq!(at(3), 1625); // between samples 1 and 2 (linear would give 1500)
//! assert_eq!(at(8), 0); // one loop later: back to the start
//! ```

use core::num::{NonZeroU64, NonZeroUsize};

use crate::units::{Angle, Microseconds, Millis};

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
}

/// Fraction bits of the interpolation parameter (`t` in Q16, 1.0 = 65 536).
const FRAC_BITS: u32 = 16;
const ONE: i64 = 1 << FRAC_BITS;

/// Maps frame indices to loop positions and interpolated offsets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Playback {
    /// Loop duration in µs (≤ 2^32 · 1000 < 2^42).
    loop_us: NonZeroU64,
    /// Frame period in µs (≥ 1).
    frame_us: u32,
    /// Samples per loop.
    samples: NonZeroUsize,
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
    /// [`PlaybackError::NoSamples`] if the respective parameter is zero.
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
        // The divisions cannot fail (loop_us ≥ 1); checked forms keep any
        // panic path out of the frame path.
        let loop_us = self.loop_us.get() as u128;
        // frame < 2^64, frame_us < 2^32: the product fits u128.
        let t = match (frame as u128 * self.frame_us as u128).checked_rem(loop_us) {
            Some(t) => t,
            None => 0,
        };
        // t < 2^42, samples < 2^64, · 2^16: < 2^122.
        let pos = match (t * self.samples.get() as u128 * ONE as u128).checked_div(loop_us) {
            Some(p) => p,
            None => 0,
        };
        let index = (pos >> FRAC_BITS) as usize; // < samples
        let frac = (pos & (ONE as u128 - 1)) as u32;
        (index, frac)
    }

    /// The three offsets (pitch, roll, yaw) of frame `frame`, interpolated
    /// between samples with a cyclic Catmull-Rom spline.
    #[must_use]
    pub fn offsets<L: LoopSource + ?Sized>(&self, frame: u64, loops: [&L; 3]) -> [Angle; 3] {
        let (index, frac) = self.position(frame);
        loops.map(|l| self.interpolate(l, index, frac))
    }

    fn interpolate<L: LoopSource + ?Sized>(&self, source: &L, i: usize, frac: u32) -> Angle {
        let n = self.samples.get();
        // Neighbours i−1, i, i+1, i+2, wrapping at the seam (i < n, so the
        // successor i + 1 ≤ n cannot overflow).
        let succ = |k: usize| if k + 1 >= n { 0 } else { k + 1 };
        let at = |k: usize| source.angle(k).millidegrees() as i64;
        let p0 = at(if i == 0 { n - 1 } else { i - 1 });
        let p1 = at(i);
        if frac == 0 {
            return Angle::from_millidegrees(p1 as i32);
        }
        let p2 = at(succ(i));
        let p3 = at(succ(succ(i)));
        let t = frac as i64;
        // 2·p(t) = 2p1 + (p2 − p0)t + (2p0 − 5p1 + 4p2 − p3)t² + (3p1 − 3p2 + p3 − p0)t³.
        // |p| < 2^31, so each coefficient < 2^35 and each Horner step < 2^52.
        let a1 = p2 - p0;
        let a2 = 2 * p0 - 5 * p1 + 4 * p2 - p3;
        let a3 = 3 * (p1 - p2) + p3 - p0;
        let h = ((a3 * t) >> FRAC_BITS) + a2;
        let h = ((h * t) >> FRAC_BITS) + a1;
        // Keep one more bit for rounding: (h·t) / 2^16 + 2p1, then halve with rounding.
        let twice = ((h * t) >> FRAC_BITS) + 2 * p1;
        let value = (twice + 1).div_euclid(2);
        Angle::from_millidegrees(value.clamp(i32::MIN as i64, i32::MAX as i64) as i32)
    }
}
