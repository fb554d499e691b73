//! How loop samples are stored.
//!
//! Three storage types implement [`Sample`]:
//! - [`Integral16`] (the firmware's): the engine's own `i16` samples of the smoothed
//!   integral, 2 bytes a sample, with the loop's [`LoopScale`] (a Q-format
//!   affine map to angles) kept next to them by
//!   [`Trajectory`](super::Trajectory). Storing the integral as it is
//!   computed saves a pass over the loop at boot; the map costs one multiply
//!   and one shift per played sample.
//! - [`Mdeg16`]: `i16` in **millidegrees** (1 LSB = 0.001°), 2 bytes a
//!   sample, range ±32.767° — wider than every anatomical limit of Table 1.
//! - `f32`: degrees, 4 bytes a sample.
//!
//! All are filled from the same integer pipeline: the engine maps each value
//! to *fine* units of 1/256 millidegree with the loop's scale and the storage
//! type rounds it, so `Mdeg16`, `f32` and `Integral16` read through its scale agree
//! within half a millidegree (half an `Mdeg16` LSB) by construction.

use crate::units::{Angle, AngleRange};

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Mdeg16 {}
    impl Sealed for super::Integral16 {}
    impl Sealed for f32 {}
}

/// Fine units per millidegree: the engine's output resolution (1/256 m°).
pub const FINE_PER_MDEG: i32 = 256;

/// A stored loop sample. Implemented by [`Integral16`], [`Mdeg16`] and `f32`; sealed.
pub trait Sample: Copy + PartialEq + core::fmt::Debug + sealed::Sealed {
    /// The neutral value, for `const` initialisation of static buffers.
    const ZERO: Self;
    /// Bytes a sample occupies.
    const BYTES: usize;
    /// Whether a [`Trajectory`](super::Trajectory) keeps the engine's samples
    /// as they are, with their [`LoopScale`] (`true`), or maps them to angles
    /// once after generation (`false`).
    #[doc(hidden)]
    const KEEPS_SCALE: bool = false;

    /// Stores an intermediate engine value (|v| < 2¹⁵); exact for both types.
    #[doc(hidden)]
    fn from_scratch(v: i16) -> Self;
    /// Reads back a value stored by [`Sample::from_scratch`].
    #[doc(hidden)]
    fn to_scratch(self) -> i16;
    /// The sample for `fine` units of 1/256 millidegree.
    fn from_fine(fine: i32) -> Self;
    /// The stored value in fine units (exact inverse of [`Sample::from_fine`]
    /// for `f32`; millidegrees × 256 for [`Mdeg16`]).
    fn fine(self) -> i32;
    /// The stored angle, rounded to the nearest millidegree.
    fn angle(self) -> Angle;
    /// The angle of a sample stored with `scale` (rounded to the nearest
    /// millidegree). Only [`Integral16`] is ever stored with another scale than
    /// [`LoopScale::MDEG`]; the others read as [`Sample::angle`].
    #[inline]
    fn angle_in(self, _scale: &LoopScale) -> Angle {
        self.angle()
    }
    /// Feeds the stored representation (little-endian bytes) to a checksum.
    fn hash_into(self, h: &mut Fnv1a);
}

/// How the engine's `i16` samples map to angles: a Q-format affine map to
/// fine units of 1/256 millidegree,
///
/// ```text
/// fine = (((raw − low) mod 2¹⁶) · m >> shift) − offset
/// ```
///
/// The samples are the loop's smoothed integral, wrapping in 16 bits; a loop
/// spans at most 65535 raw units from its lowest sample `low`, so the
/// unsigned 16-bit difference is exact. `offset` makes the loop's start map
/// to exactly 0. `m` < 2¹⁵, so the product stays below 2³¹.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopScale {
    /// The raw value of the loop's lowest sample.
    pub low: i16,
    /// Multiplier: fine units per raw unit, times 2^`shift`.
    pub m: i32,
    /// Right shift after the multiply.
    pub shift: u8,
    /// Fine units subtracted after the shift: the start's scaled offset.
    pub offset: i32,
}

impl LoopScale {
    /// Every raw value maps to 0 (the neutral pose): the scale of a loop not
    /// generated yet. All bits zero, so a `static` trajectory stays in
    /// `.bss` and costs no flash.
    pub const NEUTRAL: Self = Self {
        low: 0,
        m: 0,
        shift: 0,
        offset: 0,
    };

    /// Raw units are millidegrees: fine = raw · 256 (the finalised
    /// storages): (raw + 2¹⁵)·256 − 2¹⁵·256.
    pub const MDEG: Self = Self {
        low: i16::MIN,
        m: FINE_PER_MDEG,
        shift: 0,
        offset: 32_768 * FINE_PER_MDEG,
    };

    /// `raw` in fine units of 1/256 millidegree.
    #[inline]
    #[must_use]
    pub const fn fine(&self, raw: i16) -> i32 {
        ((raw.wrapping_sub(self.low) as u16 as i32 * self.m) >> self.shift) - self.offset
    }

    /// `raw` as an angle, rounded to the nearest millidegree like [`Mdeg16`].
    #[inline]
    #[must_use]
    pub fn angle(&self, raw: i16) -> Angle {
        Mdeg16::from_fine(self.fine(raw)).angle()
    }

    /// Feeds the scale (little-endian bytes) to a checksum.
    pub fn hash_into(&self, h: &mut Fnv1a) {
        h.write(&self.low.to_le_bytes());
        h.write(&self.m.to_le_bytes());
        h.write(&[self.shift]);
        h.write(&self.offset.to_le_bytes());
    }
}

/// The loop's smoothed integral in 16 bits (wrapping `i16`), as the engine
/// computes it: a raw value that means an angle only through its loop's
/// [`LoopScale`], which [`Trajectory`](super::Trajectory) keeps next to the
/// samples (not a fixed-point angle: the scale differs from loop to loop).
///
/// Outside a trajectory (e.g. [`generate_into`](super::generate_into)) the
/// engine finalises the loop and an `Integral16` holds millidegrees, read with
/// [`LoopScale::MDEG`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(transparent)]
pub struct Integral16(pub i16);

impl Sample for Integral16 {
    const ZERO: Self = Integral16(0);
    const BYTES: usize = 2;
    const KEEPS_SCALE: bool = true;

    #[inline]
    fn from_scratch(v: i16) -> Self {
        Integral16(v)
    }
    #[inline]
    fn to_scratch(self) -> i16 {
        self.0
    }
    #[inline]
    fn from_fine(fine: i32) -> Self {
        Integral16(Mdeg16::from_fine(fine).0)
    }
    // Read without its scale (the finalised paper loop, `LoopScale::MDEG`),
    // an Integral16 sample is an `Mdeg16`.
    #[inline]
    fn fine(self) -> i32 {
        Mdeg16(self.0).fine()
    }
    #[inline]
    fn angle(self) -> Angle {
        Mdeg16(self.0).angle()
    }
    #[inline]
    fn angle_in(self, scale: &LoopScale) -> Angle {
        scale.angle(self.0)
    }
    fn hash_into(self, h: &mut Fnv1a) {
        Mdeg16(self.0).hash_into(h);
    }
}

/// An angle stored in an `i16` as millidegrees (1 LSB = 0.001°).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(transparent)]
pub struct Mdeg16(pub i16);

impl Mdeg16 {
    /// The angles it holds: ±32.767° (−32.768° is left out, so that the
    /// range is symmetric).
    pub const RANGE: AngleRange = AngleRange {
        min: Angle::from_millidegrees(-(i16::MAX as i32)),
        max: Angle::from_millidegrees(i16::MAX as i32),
    };
}

impl Sample for Mdeg16 {
    const ZERO: Self = Mdeg16(0);
    const BYTES: usize = 2;

    #[inline]
    fn from_scratch(v: i16) -> Self {
        Mdeg16(v)
    }
    #[inline]
    fn to_scratch(self) -> i16 {
        self.0
    }
    #[inline]
    fn from_fine(fine: i32) -> Self {
        // Round half up. The engine keeps |fine| ≤ 32767·256 (ranges are
        // validated against the i16 range), so the cast never wraps.
        Mdeg16(((fine + FINE_PER_MDEG / 2) >> 8) as i16)
    }
    #[inline]
    fn fine(self) -> i32 {
        i32::from(self.0) * FINE_PER_MDEG
    }
    #[inline]
    fn angle(self) -> Angle {
        Angle::from_millidegrees(i32::from(self.0))
    }
    fn hash_into(self, h: &mut Fnv1a) {
        h.write(&self.0.to_le_bytes());
    }
}

impl Sample for f32 {
    const ZERO: Self = 0.0;
    const BYTES: usize = 4;

    #[inline]
    fn from_scratch(v: i16) -> Self {
        f32::from(v)
    }
    #[inline]
    fn to_scratch(self) -> i16 {
        self as i16
    }
    #[inline]
    fn from_fine(fine: i32) -> Self {
        fine as f32 / (FINE_PER_MDEG * Angle::SCALE) as f32
    }
    fn fine(self) -> i32 {
        // |fine| < 2²³ and f32 keeps 24 bits, so rounding in f64 recovers it exactly.
        let f = f64::from(self) * f64::from(FINE_PER_MDEG * Angle::SCALE);
        (if f < 0.0 { f - 0.5 } else { f + 0.5 }) as i32
    }
    fn angle(self) -> Angle {
        // The same rounding as `Mdeg16`, so both storages report the same angle.
        Mdeg16::from_fine(self.fine()).angle()
    }
    fn hash_into(self, h: &mut Fnv1a) {
        h.write(&self.to_bits().to_le_bytes());
    }
}

/// 32-bit FNV-1a, the buffer checksum printed by the firmware and recomputed by the tests.
#[derive(Clone, Copy, Debug)]
pub struct Fnv1a(u32);

impl Fnv1a {
    const OFFSET: u32 = 0x811c_9dc5;
    const PRIME: u32 = 0x0100_0193;

    /// A fresh hasher.
    #[must_use]
    pub const fn new() -> Self {
        Self(Self::OFFSET)
    }

    /// Feeds bytes.
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u32::from(b)).wrapping_mul(Self::PRIME);
        }
    }

    /// The hash so far.
    #[must_use]
    pub const fn finish(&self) -> u32 {
        self.0
    }
}

impl Default for Fnv1a {
    fn default() -> Self {
        Self::new()
    }
}
