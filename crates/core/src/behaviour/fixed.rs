//! Fixed-point helpers of the frame path: 32-bit multiplies only (ARMv6-M
//! has no 64-bit multiply and no divide instruction); and frame counting
//! ([`ahead`]).
//!
//! Convention: a *fraction* is a `u32` in Q16 (`0..=65 536` is 0..=1), a
//! signed one an `i32` in Q16. Angles are `i32` millidegrees.
//! Every helper rounds to the nearest result (error ≤ ½ LSB) and is exact at
//! the ends (`× 0 = 0`, `× 1 = x`).

/// 1.0 in Q16.
pub(crate) const ONE: u32 = 1 << 16;

/// `x · f` for a Q16 fraction `f ≤ 1`, rounded; any `x`.
///
/// `x = hi·2¹⁶ + lo` (`lo` unsigned): `hi·f` fits `i32` because `|hi| ≤ 2¹⁵`
/// and `f ≤ 2¹⁶` (and `hi = 2¹⁵` cannot occur), `lo·f + 2¹⁵ < 2³²`.
#[inline]
pub(crate) const fn mul(x: i32, f: u32) -> i32 {
    debug_assert!(f <= ONE);
    let hi = x >> 16;
    let lo = (x & 0xFFFF) as u32;
    let low = (lo.wrapping_mul(f).wrapping_add(1 << 15)) >> 16;
    hi.wrapping_mul(f as i32).wrapping_add(low as i32)
}

/// `x · f` for a signed Q16 fraction `f ∈ [−1, 1]`, rounded (half away from
/// the carrier's zero, symmetric in `f`).
#[inline]
pub(crate) const fn mul_signed(x: i32, f: i32) -> i32 {
    if f < 0 {
        mul(x, f.unsigned_abs()).wrapping_neg()
    } else {
        mul(x, f as u32)
    }
}

/// The smootherstep `S(x) = x³·(6x² − 15x + 10)` of a Q16 fraction (1 at
/// and beyond 1): 0 and 1 at the ends with zero first and second
/// derivatives, so a ramp along it is continuous in value, velocity and
/// acceleration (C2). Four rounded multiplies: within 2·2⁻¹⁶ of the exact
/// value.
#[inline]
pub(crate) const fn smootherstep(x: u32) -> u32 {
    if x >= ONE {
        return ONE;
    }
    // x < 1: x² < 2³² exactly. The quadratic is in [1, 10] on [0, 1].
    let x2 = x.wrapping_mul(x).wrapping_add(1 << 15) >> 16;
    let inner = (6 * x2 + 10 * ONE - 15 * x) as i32;
    // Rounding may pass 1 by a count just below x = 1.
    let s = mul(mul(mul(inner, x), x), x) as u32;
    if s > ONE { ONE } else { s }
}

/// Longest duration with a reciprocal, in frames.
pub(crate) const MAX_FRAMES: u32 = u16::MAX as u32;

/// The reciprocal of a duration of `frames` frames (`2..=MAX_FRAMES`):
/// `⌈2³² / frames⌉`, so that `t · inverse` is `t / frames` in Q32 for
/// `t < frames`, never below it (no division on the frame path).
#[must_use]
pub(crate) const fn inverse(frames: u32) -> u32 {
    let frames = if frames < 2 {
        2
    } else if frames > MAX_FRAMES {
        MAX_FRAMES
    } else {
        frames
    };
    (1_u64 << 32).div_ceil(frames as u64) as u32
}

/// `t / frames` in Q16, rounded, from `t < frames` and
/// [`inverse`]`(frames)`: at most `65 535`.
#[inline]
pub(crate) const fn progress(t: u32, inverse: u32) -> u32 {
    // t ≤ F − 1 and ⌈2³²/F⌉ < 2³²/F + 1: t·inverse + 2¹⁵ < 2³² − 2³²/F + F + 2¹⁵,
    // below 2³² − 2¹⁵ for F < 2¹⁶.
    t.wrapping_mul(inverse).wrapping_add(1 << 15) >> 16
}

/// Frames from `from` to `frame` if it lies after `from`, else `u32::MAX`
/// (not an event to wait for).
#[inline]
pub(crate) const fn ahead(frame: u32, from: u32) -> u32 {
    let d = frame.wrapping_sub(from);
    if d as i32 > 0 { d } else { u32::MAX }
}
