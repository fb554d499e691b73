//! Frame playback: which point of the loop a frame shows.
//!
//! A loop of `N` samples is played over a configurable duration, independent of
//! `N` and of the frame rate. The position of frame `k` is
//! `k · frame_period mod loop_duration` in exact integer arithmetic, so there
//! is no drift however long the head runs: [`Playback::position`] computes it
//! from `k`, [`Player`] (the frame path) keeps it from frame to frame with
//! additions only. Between samples the loop is interpolated with a cyclic
//! Catmull-Rom spline (cubic Hermite with central difference tangents):
//! continuous in value and velocity everywhere, also across the seam from
//! sample `N − 1` back to sample 0.
//!
//! # The spline in 32 bits
//!
//! With the four samples `p₀..p₃` around a segment and their differences
//! `d₀ = p₁ − p₀`, `d₁ = p₂ − p₁`, `d₂ = p₃ − p₂`, the segment at `t ∈ [0, 1)` is
//! `2p(t) = 2p₁ + a₁t + a₂t² + a₃t³` with `a₁ = d₀ + d₁`,
//! `a₂ = −2d₀ + 3d₁ − d₂`, `a₃ = d₀ − 2d₁ + d₂`, that is
//! `2p(t) = 2p₁ + w₀(t)·d₀ + w₁(t)·d₁ + w₂(t)·d₂` with the weights
//! `w₀ = t − 2t² + t³`, `w₁ = t + 3t² − 2t³`, `w₂ = t³ − t²`. The weights
//! depend on `t` alone, which the three axes share: a frame works them out
//! once ([`Weights`], `t` in Q12, `t²` and `t³` rounded down to Q12) and each
//! axis then takes three products (1.67 frames per sample at the defaults:
//! 4096 steps are far finer than the frames). `|w₀|, |w₂| < 0.15` and
//! `0 ≤ w₁ ≤ 2`: when neighbouring samples differ by less than 2¹⁵ m° (32.8°;
//! the idle loops move a fraction of a degree per sample) and lie within
//! ±2²⁹ m°, the sum stays below `2.3·2¹²·2¹⁵` < 2³¹: `i32`. Larger steps
//! take the same formula in `i64`. The sum is rounded down (`>> 12`); the
//! value is `p₁` plus half of it, rounded half up.
//!
//! ```
//! use idle_head_core::playback::{LoopSource, Playback};
//! use idle_head_core::{Angle, Microseconds, Millis};
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

mod player;
mod timing;

pub use player::{Axes, Cursor, Player};
pub use timing::{LoopSource, Playback, PlaybackError};
