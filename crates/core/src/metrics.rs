//! Loop quality metrics: continuity, liveliness and range.
//!
//! For a loop x of length N taken cyclically, with d1(n) = x(n+1) − x(n) and
//! d2(n) = d1(n+1) − d1(n):
//! - **continuity**: max|d1| / P95|d1| and max|d2| / P95|d2|. A jump anywhere,
//!   the seam included, makes the maximum stand out from the 95th percentile.
//! - **liveliness**: the smallest mean |d1| over 10 equal segments divided by
//!   the mean |d1| of the whole loop (1 = equally lively everywhere, 0 = a
//!   segment that stands still).
//! - **range**: the smallest and largest value, and the value at index 0.
//!
//! P95 is the ⌈0.95·N⌉-th smallest value (nearest-rank). Values are taken in the
//! engine's fine units (1/256 millidegree), so both storage types measure the
//! same way.

use crate::motion::Sample;
use crate::units::Angle;

/// Segments used for liveliness.
pub const SEGMENTS: usize = 10;

/// The metrics of one loop.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopMetrics {
    /// max|d1| / P95|d1|.
    pub velocity_ratio: f32,
    /// max|d2| / P95|d2|.
    pub acceleration_ratio: f32,
    /// min over segments of mean|d1|, divided by the overall mean|d1|.
    pub liveliness: f32,
    /// Smallest value.
    pub min: Angle,
    /// Largest value.
    pub max: Angle,
    /// Value at index 0 (the start of the loop).
    pub start: Angle,
}

impl LoopMetrics {
    /// Measures `samples`, using `scratch` (at least as long) for the percentiles.
    ///
    /// Returns `None` when the loop is shorter than [`SEGMENTS`] samples or
    /// `scratch` is too short.
    #[must_use]
    pub fn measure<S: Sample>(samples: &[S], scratch: &mut [i32]) -> Option<Self> {
        let n = samples.len();
        if n < SEGMENTS || scratch.len() < n {
            return None;
        }
        let x = |i: usize| samples.get(i % n).map_or(0, |s| s.fine());
        let d1 = |i: usize| x(i + 1) - x(i);
        let d2 = |i: usize| d1(i + 1) - d1(i);

        let scratch = &mut scratch[..n];
        for (i, s) in scratch.iter_mut().enumerate() {
            *s = d1(i).abs();
        }
        let total: i64 = scratch.iter().map(|&v| i64::from(v)).sum();
        let velocity_ratio = ratio_to_p95(scratch);

        let mut liveliness = f32::INFINITY;
        for k in 0..SEGMENTS {
            let (a, b) = (k * n / SEGMENTS, (k + 1) * n / SEGMENTS);
            let seg: i64 = (a..b).map(|i| i64::from(d1(i).abs())).sum();
            let mean_seg = seg as f32 / (b - a) as f32;
            liveliness = liveliness.min(mean_seg);
        }
        let mean = total as f32 / n as f32;
        liveliness = if mean > 0.0 { liveliness / mean } else { 0.0 };

        for (i, s) in scratch.iter_mut().enumerate() {
            *s = d2(i).abs();
        }
        let acceleration_ratio = ratio_to_p95(scratch);

        let angle = |s: &S| s.angle();
        let min = samples.iter().map(angle).min()?;
        let max = samples.iter().map(angle).max()?;
        let start = samples.first().map(angle)?;
        Some(Self {
            velocity_ratio,
            acceleration_ratio,
            liveliness,
            min,
            max,
            start,
        })
    }
}

/// max / P95 of non-negative values (reorders `v`); ∞ when P95 is 0 but the
/// maximum is not, 1 when both are 0.
fn ratio_to_p95(v: &mut [i32]) -> f32 {
    let n = v.len();
    let rank = (n * 95).div_ceil(100).max(1) - 1;
    let max = v.iter().copied().max().unwrap_or(0);
    let (_, p95, _) = v.select_nth_unstable(rank);
    let p95 = *p95;
    match (max, p95) {
        (0, _) => 1.0,
        (_, 0) => f32::INFINITY,
        (m, p) => m as f32 / p as f32,
    }
}
