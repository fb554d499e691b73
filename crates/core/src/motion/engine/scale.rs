//! From the integral X to angles: the multiplier both closures scale with,
//! and the mapping of stored samples to their storage's units.

use crate::motion::storage::{LoopScale, Sample};

/// `num/den` (fine units per X unit) as a multiplier `m / 2^shift`, rounded
/// down so scaled values never overshoot, with `m` as large as the product
/// `ΔX·m` allows in `i32` for |ΔX| ≤ `vmax`: m·vmax + 2^shift ≤ 2³¹.
/// `None` if the ratio does not fit.
pub(super) fn multiplier(num: i64, den: i64, vmax: i64) -> Option<(i32, u32)> {
    if num <= 0 || den <= 0 || vmax <= 0 {
        return None;
    }
    let m_max = ((1u64 << 30) / vmax as u64).max(1);
    // ratio · 2³⁰, exact floor (num < 2²⁴): one division.
    let r = ((num as u64) << 30) / den as u64;
    // The fewest dropped bits that bring r to m_max or below: r's length
    // less m_max's, or one more.
    let mut drop = (64 - r.leading_zeros()).saturating_sub(64 - m_max.leading_zeros());
    if r.checked_shr(drop).unwrap_or(0) > m_max {
        drop += 1;
    }
    let m = r.checked_shr(drop).unwrap_or(0);
    if drop > 30 || m == 0 {
        return None;
    }
    Some((m as i32, 30 - drop))
}

/// Converts the integral X to walk steps δ for [`Trace::smoothed`](super::Trace::smoothed)
/// (paper form; the seamless form's b-steps count half).
pub(super) fn trace_scale(shift: u32, qq: i32, w: usize) -> f32 {
    (1u64 << shift) as f32 / (qq as f32 * w as f32)
}

/// Maps samples stored with `scale` to the storage's own units
/// ([`LoopScale::MDEG`] afterwards); nothing to do if they are already.
pub(in crate::motion) fn finalise<S: Sample>(out: &mut [S], scale: &LoopScale) {
    if *scale == LoopScale::MDEG {
        return;
    }
    for o in out {
        *o = S::from_fine(scale.fine(o.to_scratch()));
    }
}
