//! Fixed-point helpers of the frame path: 32-bit multiplies only (ARMv6-M
//! has no 64-bit multiply and no divide instruction); durations and their
//! reciprocals ([`Span`]) and waiting on the clock ([`ahead`]).
//!
//! The clock is the frame's [`Timestamp`](crate::Timestamp) in µs, its low
//! 32 bits (it wraps every 71 minutes): every time kept is compared by its
//! difference to another, and no two compared lie [`MAX_SPAN`] apart.
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

/// Longest duration with a reciprocal, in its own (shifted) units.
const MAX_UNITS: u32 = u16::MAX as u32;

/// Longest duration on the frame path's clock, µs (about 18 minutes): any
/// two times it compares lie less than 2³¹ µs apart.
pub(crate) const MAX_SPAN: u32 = 1 << 30;

/// The reciprocal of a duration of `units` (`2..=MAX_UNITS`):
/// `⌈2³² / units⌉`, so that `t · inverse` is `t / units` in Q32 for
/// `t < units`, never below it (no division on the frame path).
#[must_use]
const fn inverse(units: u32) -> u32 {
    let units = if units < 2 {
        2
    } else if units > MAX_UNITS {
        MAX_UNITS
    } else {
        units
    };
    (1_u64 << 32).div_ceil(units as u64) as u32
}

/// `t / units` in Q16, rounded, from `t < units` and
/// [`inverse`]`(units)`: at most `65 535`.
#[inline]
const fn progress(t: u32, inverse: u32) -> u32 {
    // t ≤ F − 1 and ⌈2³²/F⌉ < 2³²/F + 1: t·inverse + 2¹⁵ < 2³² − 2³²/F + F + 2¹⁵,
    // below 2³² − 2¹⁵ for F < 2¹⁶.
    t.wrapping_mul(inverse).wrapping_add(1 << 15) >> 16
}

/// A duration on the frame path's clock (µs) and its reciprocal: how far
/// into it a time lies, as a Q16 fraction, from a shift and one 32-bit
/// multiply. The duration is counted in units of `2^shift` µs, the fewest
/// that bring it below 2¹⁶ units (rounded up, so that a time inside it is
/// inside it in units too): the fraction is within 2⁻¹⁵ of the exact one
/// (and exact at the start), whatever the frame rate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Span {
    /// The duration, µs (`2..=MAX_SPAN`).
    len: u32,
    inverse: u32,
    shift: u8,
}

impl Span {
    /// A span that has ended (length 0: every time lies past it).
    pub(crate) const ENDED: Self = Self {
        len: 0,
        inverse: 0,
        shift: 0,
    };

    /// A span of `us` µs, within `2..=MAX_SPAN`.
    pub(crate) const fn new(us: u32) -> Self {
        let len = if us < 2 {
            2
        } else if us > MAX_SPAN {
            MAX_SPAN
        } else {
            us
        };
        let mut shift = 0;
        while (len - 1) >> shift >= MAX_UNITS {
            shift += 1;
        }
        Self {
            len,
            inverse: inverse(((len - 1) >> shift) + 1),
            shift: shift as u8,
        }
    }

    /// The duration, µs.
    #[inline]
    pub(crate) const fn len(&self) -> u32 {
        self.len
    }

    /// `t / len` in Q16 (`0..65 536`), for `t < len`.
    #[inline]
    pub(crate) const fn progress(&self, t: u32) -> u32 {
        progress(t >> self.shift, self.inverse)
    }
}

/// µs from `from` to `at` if it lies after `from`, else `u32::MAX` (not
/// an event to wait for).
#[inline]
pub(crate) const fn ahead(at: u32, from: u32) -> u32 {
    let d = at.wrapping_sub(from);
    if d as i32 > 0 { d } else { u32::MAX }
}
