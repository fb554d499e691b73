//! Physical units as types.
//!
//! Conventions (fixed, documented once here):
//! - [`Angle`]: signed angle in **millidegrees** (1 LSB = 0.001°) held in an `i32`.
//! - [`Microseconds`]: pulse width or period in **microseconds** held in a `u32`.
//! - [`Millis`]: duration in **milliseconds** held in a `u32`.
//! - [`DegreesPerSecond`], [`DegreesPerSecondSquared`]: angular speed and
//!   acceleration in **whole degrees** per second (squared) held in a `u32`.
//! - [`MilliHertz`]: frequency in **millihertz** held in a `u32`.
//! - [`Percent`]: a whole percentage, `0..=100`, held in a `u8`.
//!
//! Angles and ranges display in degrees, as a user writes them: `-23°`,
//! `4.5°`, `-0.25°`, `-23°..32°` (exact: no float formatting).

use crate::text::{Describe, Text, display_from_describe};
use core::ops::{Add, Neg, Sub};

/// A signed angle in millidegrees (1 LSB = 0.001°).
///
/// ```
/// use idle_head_core::Angle;
/// assert_eq!(Angle::from_degrees(-4).millidegrees(), -4000);
/// assert_eq!(Angle::from_millidegrees(1500).to_degrees_f32(), 1.5);
/// assert_eq!(Angle::from_millidegrees(-250).to_string(), "-0.25°");
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Angle(i32);

impl Angle {
    /// Millidegrees per degree.
    pub const SCALE: i32 = 1000;
    /// The neutral angle.
    pub const ZERO: Self = Self(0);

    /// An angle of `deg` whole degrees (saturating far outside any servo's reach).
    #[must_use]
    pub const fn from_degrees(deg: i32) -> Self {
        Self(deg.saturating_mul(Self::SCALE))
    }

    /// An angle of `mdeg` millidegrees.
    #[must_use]
    pub const fn from_millidegrees(mdeg: i32) -> Self {
        Self(mdeg)
    }

    /// The angle in millidegrees.
    #[must_use]
    pub const fn millidegrees(self) -> i32 {
        self.0
    }

    /// The angle in degrees, for display and plotting.
    #[must_use]
    pub fn to_degrees_f32(self) -> f32 {
        self.0 as f32 / Self::SCALE as f32
    }

    /// The nearest angle to `deg` degrees (saturating at the `i32` range).
    #[must_use]
    pub fn from_degrees_f32(deg: f32) -> Self {
        // `as` saturates and maps NaN to 0.
        Self(libm::roundf(deg * Self::SCALE as f32) as i32)
    }

    /// `self` clamped into `[lo, hi]` (returns `lo` if `lo > hi`, never panics).
    #[must_use]
    pub const fn clamp_to(self, lo: Self, hi: Self) -> Self {
        if self.0 < lo.0 {
            lo
        } else if self.0 > hi.0 {
            hi
        } else {
            self
        }
    }

    /// Saturating addition.
    #[must_use]
    pub const fn saturating_add(self, rhs: Self) -> Self {
        Self(self.0.saturating_add(rhs.0))
    }

    /// Saturating subtraction.
    #[must_use]
    pub const fn saturating_sub(self, rhs: Self) -> Self {
        Self(self.0.saturating_sub(rhs.0))
    }
}

impl Describe for Angle {
    fn describe(&self, out: &mut dyn Text) {
        let sign = if self.0 < 0 { "-" } else { "" };
        out.str(sign)
            .milli(u64::from(self.0.unsigned_abs()))
            .str("°");
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Angle {
    fn format(&self, f: defmt::Formatter<'_>) {
        // The digits `Text::milli` writes.
        let abs = self.0.unsigned_abs();
        let whole = abs / Self::SCALE as u32;
        let (fraction, digits) = crate::text::significant(abs % Self::SCALE as u32);
        let sign = if self.0 < 0 { "-" } else { "" };
        // The arms differ in their format strings only (which defmt interns).
        // The sign is part of the format string, not a `{=str}` argument,
        // which a `{:?}` around the angle (a derived `Format`) would quote.
        #[allow(clippy::match_same_arms)]
        match (sign.is_empty(), digits) {
            (true, 0) => defmt::write!(f, "{=u32}°", whole),
            (true, 1) => defmt::write!(f, "{=u32}.{=u32}°", whole, fraction),
            (true, 2) => defmt::write!(f, "{=u32}.{=u32:02}°", whole, fraction),
            (true, _) => defmt::write!(f, "{=u32}.{=u32:03}°", whole, fraction),
            (false, 0) => defmt::write!(f, "-{=u32}°", whole),
            (false, 1) => defmt::write!(f, "-{=u32}.{=u32}°", whole, fraction),
            (false, 2) => defmt::write!(f, "-{=u32}.{=u32:02}°", whole, fraction),
            (false, _) => defmt::write!(f, "-{=u32}.{=u32:03}°", whole, fraction),
        }
    }
}

impl Add for Angle {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        self.saturating_add(rhs)
    }
}

impl Sub for Angle {
    type Output = Self;
    fn sub(self, rhs: Self) -> Self {
        self.saturating_sub(rhs)
    }
}

impl Neg for Angle {
    type Output = Self;
    fn neg(self) -> Self {
        Self(self.0.saturating_neg())
    }
}

/// A duration or pulse width in microseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Microseconds(pub u32);

impl Microseconds {
    /// The value in microseconds.
    #[must_use]
    pub const fn get(self) -> u32 {
        self.0
    }
}

/// A frame's time: microseconds since the head's first frame. The frame
/// engine is timed on it, not on frame counts, so that the motion is the
/// same in time at any frame rate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Timestamp(pub u64);

impl Timestamp {
    /// The time of frame `frame` of frames `period` apart (saturating).
    #[must_use]
    pub const fn of_frame(frame: u64, period: Microseconds) -> Self {
        Self(frame.saturating_mul(period.0 as u64))
    }

    /// The value in microseconds.
    #[must_use]
    pub const fn micros(self) -> u64 {
        self.0
    }

    /// The value in whole milliseconds.
    #[must_use]
    pub const fn millis(self) -> u64 {
        self.0 / 1000
    }

    /// The low 32 bits: the frame path's wrapping clock (71 minutes
    /// round), on which every time it keeps is compared by difference.
    #[must_use]
    pub const fn wrapping(self) -> u32 {
        self.0 as u32
    }
}

/// A duration in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Millis(pub u32);

impl Millis {
    /// The value in milliseconds.
    #[must_use]
    pub const fn get(self) -> u32 {
        self.0
    }
}

/// A length in millimetres (the trackers' positions, the height of a
/// visitor's eyes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Millimetres(pub i32);

impl Millimetres {
    /// The value in millimetres.
    #[must_use]
    pub const fn get(self) -> i32 {
        self.0
    }
}

/// Angular speed in whole degrees per second.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DegreesPerSecond(pub u32);

/// Angular acceleration in whole degrees per second squared.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DegreesPerSecondSquared(pub u32);

/// A frequency in millihertz (1 LSB = 0.001 Hz).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MilliHertz(pub u32);

/// A whole percentage, `0..=100`.
///
/// ```
/// use idle_head_core::units::Percent;
/// assert_eq!(Percent::new(40).map(Percent::get), Some(40));
/// assert_eq!(Percent::new(101), None);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Percent(u8);

impl Percent {
    /// 0 %.
    pub const ZERO: Self = Self(0);
    /// 50 %.
    pub const HALF: Self = Self(50);
    /// 100 %.
    pub const FULL: Self = Self(100);

    /// `value` percent, if it is at most 100.
    #[must_use]
    pub const fn new(value: u8) -> Option<Self> {
        if value <= 100 {
            Some(Self(value))
        } else {
            None
        }
    }

    /// The percentage.
    #[must_use]
    pub const fn get(self) -> u8 {
        self.0
    }
}

/// An inclusive angle range `[min, max]`, displayed as `min..max`.
///
/// ```
/// use idle_head_core::AngleRange;
/// assert_eq!(AngleRange::degrees(-23, 32).to_string(), "-23°..32°");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct AngleRange {
    /// Lower bound (α1 in the paper).
    pub min: Angle,
    /// Upper bound (α2 in the paper).
    pub max: Angle,
}

impl AngleRange {
    /// `[min, max]` in whole degrees.
    #[must_use]
    pub const fn degrees(min: i32, max: i32) -> Self {
        Self {
            min: Angle::from_degrees(min),
            max: Angle::from_degrees(max),
        }
    }

    /// Whether `a` lies inside the range (inclusive).
    #[must_use]
    pub const fn contains(&self, a: Angle) -> bool {
        self.min.0 <= a.0 && a.0 <= self.max.0
    }

    /// Whether `other` lies entirely inside this range.
    #[must_use]
    pub const fn contains_range(&self, other: &Self) -> bool {
        self.contains(other.min) && self.contains(other.max)
    }

    /// The width `max - min` in millidegrees (negative for an inverted range).
    #[must_use]
    pub const fn span_millidegrees(&self) -> i64 {
        self.max.0 as i64 - self.min.0 as i64
    }
}

impl Describe for AngleRange {
    fn describe(&self, out: &mut dyn Text) {
        out.with(&self.min).str("..").with(&self.max);
    }
}

display_from_describe!(Angle, AngleRange);

#[cfg(feature = "defmt")]
impl defmt::Format for AngleRange {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "{}..{}", self.min, self.max);
    }
}
