//! How loop samples are stored.
//!
//! Two storage types implement [`Sample`]:
//! - [`Mdeg16`] (default): `i16` in **millidegrees** (1 LSB = 0.001°), 2 bytes a
//!   sample, range ±32.767° — wider than every anatomical limit of Table 1.
//! - `f32`: degrees, 4 bytes a sample, for users who want the engine's full
//!   resolution (it keeps 1/256 of a millidegree).
//!
//! Both are filled from the same integer pipeline: the engine produces each
//! value in *fine* units of 1/256 millidegree and the storage type rounds it, so
//! the two agree within half a millidegree (half an `Mdeg16` LSB) by construction.

use crate::units::Angle;

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Mdeg16 {}
    impl Sealed for f32 {}
}

/// Fine units per millidegree: the engine's output resolution (1/256 m°).
pub const FINE_PER_MDEG: i32 = 256;

/// A stored loop sample. Implemented by [`Mdeg16`] and `f32`; sealed.
pub trait Sample: Copy + PartialEq + core::fmt::Debug + sealed::Sealed {
    /// The neutral value, for `const` initialisation of static buffers.
    const ZERO: Self;
    /// Bytes a sample occupies.
    const BYTES: usize;

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
    /// Feeds the stored representation (little-endian bytes) to a checksum.
    fn hash_into(self, h: &mut Fnv1a);
}

/// An angle stored in an `i16` as millidegrees (1 LSB = 0.001°).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(transparent)]
pub struct Mdeg16(pub i16);

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
