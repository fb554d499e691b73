//! The calibration of one servo ([`ServoCalibration`]) and its units: what
//! [`ServoMap`](super::ServoMap) turns into pulses and duty ticks.

use crate::axis::Axis;
use crate::units::{Angle, AngleRange, Microseconds};

/// Picoseconds per microsecond: an angle in m° times a scale in ns/° is a
/// pulse in ps.
const PS_PER_US: i64 = 1_000_000;

/// Pulse change per degree, in **nanoseconds per degree** (1 LSB = 1 ns/°).
///
/// Nanoseconds keep the usual hobby servo scale exact enough: 1000 µs per 90°
/// is 11 111 ns/° (11.111 µs/°, error 0.001 %).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NanosPerDegree(pub u32);

impl NanosPerDegree {
    /// The scale of a pulse span over an angle span, rounded to the nearest ns/°
    /// (zero if `degrees` is zero, which [`ServoCalibration::validate`] rejects).
    ///
    /// ```
    /// use idle_head_core::servo::NanosPerDegree;
    /// use idle_head_core::Microseconds;
    /// assert_eq!(NanosPerDegree::from_span(Microseconds(1000), 90), NanosPerDegree(11_111));
    /// ```
    #[must_use]
    pub const fn from_span(pulse: Microseconds, degrees: u32) -> Self {
        if degrees == 0 {
            return Self(0);
        }
        // pulse ≤ 2^32 µs = 4.3e12 ns, fits u64; the quotient fits u32 unless
        // the span is absurd, where it saturates.
        let ns = pulse.0 as u64 * 1000;
        let q = (ns + degrees as u64 / 2) / degrees as u64;
        if q > u32::MAX as u64 {
            Self(u32::MAX)
        } else {
            Self(q as u32)
        }
    }

    /// The value in nanoseconds per degree.
    #[must_use]
    pub const fn get(self) -> u32 {
        self.0
    }
}

/// PWM duty ticks, as passed to `embedded_hal::pwm::SetDutyCycle::set_duty_cycle`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Duty(pub u16);

/// Sense of rotation: whether a larger pulse turns the axis towards positive angles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Direction {
    /// pulse = neutral + angle · scale.
    Normal,
    /// pulse = neutral − angle · scale (servo mounted the other way round).
    Reversed,
}

/// A calibration rejected by [`ServoCalibration::validate`], with the rejected
/// values. Its [`Display`](core::fmt::Display) says what is wrong in microseconds and
/// degrees; [`message`](Self::message) names the field for `const` checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ServoError {
    /// `min_pulse` is not below `max_pulse`.
    PulseRangeEmpty {
        /// The rejected minimum pulse.
        min: Microseconds,
        /// The rejected maximum pulse.
        max: Microseconds,
    },
    /// `neutral` lies outside `[min_pulse, max_pulse]`.
    NeutralOutsidePulseRange {
        /// The rejected neutral pulse.
        neutral: Microseconds,
        /// The calibration's shortest pulse.
        min: Microseconds,
        /// The calibration's longest pulse.
        max: Microseconds,
    },
    /// `per_degree` is zero: every angle would map to the neutral pulse.
    ZeroPerDegree,
    /// `limits.min` is above `limits.max`.
    LimitsInverted {
        /// The rejected limits.
        limits: AngleRange,
    },
    /// The neutral angle (0°, where the servo receives its first pulse) lies outside `limits`.
    NeutralOutsideLimits {
        /// The rejected limits.
        limits: AngleRange,
    },
    /// `min_pulse` or `max_pulse` lies outside the hard bounds
    /// [`bounds::MIN_PULSE`]..=[`bounds::MAX_PULSE`] that no setting may pass.
    PulseOutsideBounds {
        /// `true` for `max_pulse`, `false` for `min_pulse`.
        max: bool,
        /// The rejected pulse.
        pulse: Microseconds,
    },
    /// An angle limit needs a pulse outside `[min_pulse, max_pulse]`: the servo cannot reach it.
    LimitUnreachable {
        /// The unreachable limit angle.
        angle: Angle,
        /// The pulse width that angle needs, in microseconds (may be negative).
        needed_us: i64,
        /// The calibration's shortest pulse.
        min: Microseconds,
        /// The calibration's longest pulse.
        max: Microseconds,
    },
}

impl ServoError {
    /// A one-line description naming the offending field, for logs and build errors.
    #[must_use]
    pub const fn message(&self) -> &'static str {
        match self {
            Self::PulseRangeEmpty { .. } => {
                "servo calibration: `min_pulse` must be below `max_pulse`"
            }
            Self::NeutralOutsidePulseRange { .. } => {
                "servo calibration: `neutral` must lie in [`min_pulse`, `max_pulse`]"
            }
            Self::ZeroPerDegree => "servo calibration: `per_degree` must not be zero",
            Self::PulseOutsideBounds { .. } => {
                "servo calibration: `min_pulse` and `max_pulse` must lie in 500..=2500 µs"
            }
            Self::LimitsInverted { .. } => {
                "servo calibration: `limits.min` must not exceed `limits.max`"
            }
            Self::NeutralOutsideLimits { .. } => {
                "servo calibration: `limits` must contain 0° (the neutral angle)"
            }
            Self::LimitUnreachable { .. } => {
                "servo calibration: an angle in `limits` needs a pulse outside [`min_pulse`, `max_pulse`]"
            }
        }
    }
}

// Its text: `impl Describe for ServoError` (driver/error.rs).
crate::text::display_from_describe!(ServoError, Degrees);

impl core::error::Error for ServoError {}

/// An angle shown in degrees with its sign and up to three decimals
/// (`+20°`, `-12.5°`, `0°`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Degrees(pub(crate) Angle);

/// Calibration of one servo and the axis it drives.
///
/// Build one with [`ServoCalibration::hobby`] and adjust fields; check it with
/// [`validate`](Self::validate) (or [`assert_valid`](Self::assert_valid) in a
/// `const` for built-in configurations, so a wrong one fails the build).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoCalibration {
    /// Pulse width at the neutral angle (0°).
    pub neutral: Microseconds,
    /// Pulse change per degree.
    pub per_degree: NanosPerDegree,
    /// Sense of rotation.
    pub direction: Direction,
    /// Shortest pulse ever written.
    pub min_pulse: Microseconds,
    /// Longest pulse ever written.
    pub max_pulse: Microseconds,
    /// Mechanical angle limits of the axis; commanded angles are clamped to them.
    pub limits: AngleRange,
}

/// Hard bounds on the pulses that no setting may pass, and the range most
/// hobby servos accept.
///
/// Analogue hobby servos are specified for 1000..2000 µs (±45° on most);
/// many travel further, to about 500..2500 µs, and some lock up, stall
/// against their end stops or reverse past that. So `min_pulse` and
/// `max_pulse` must lie in [`MIN_PULSE`]..=[`MAX_PULSE`] (`err invalid`
/// otherwise), and a calibration outside [`TYPICAL_MIN`]..=[`TYPICAL_MAX`]
/// is accepted with a warning ([`ServoCalibration::unusual`]). The angle
/// limits are bounded by the pulses: each limit's pulse must lie in
/// `[min_pulse, max_pulse]` ([`ServoError::LimitUnreachable`]), so with
/// 11.111 µs/° no limit can pass ±90° however the pulses are set.
pub mod bounds {
    use super::Microseconds;

    /// The shortest pulse any setting may write.
    pub const MIN_PULSE: Microseconds = Microseconds(500);
    /// The longest pulse any setting may write.
    pub const MAX_PULSE: Microseconds = Microseconds(2500);
    /// The shortest pulse most hobby servos are specified for.
    pub const TYPICAL_MIN: Microseconds = Microseconds(1000);
    /// The longest pulse most hobby servos are specified for.
    pub const TYPICAL_MAX: Microseconds = Microseconds(2000);
}

/// Defaults for a typical analogue hobby servo (SG90/MG90S/MG996R class).
pub mod defaults {
    use super::{Microseconds, NanosPerDegree};

    /// Neutral (centre) pulse: 1500 µs, the de-facto standard centre.
    pub const NEUTRAL: Microseconds = Microseconds(1500);
    /// 1000 µs of pulse per 90° of travel (1000..2000 µs ↔ −45°..+45°):
    /// 1 000 000 ns / 90° = 11 111.1 ns/° → 11 111 ns/°.
    pub const PER_DEGREE: NanosPerDegree = NanosPerDegree::from_span(Microseconds(1000), 90);
    /// Shortest pulse: 1000 µs, inside every hobby servo's range. (Many accept
    /// 900..2100 µs or more; widen only after checking the servo's end stops.)
    pub const MIN_PULSE: Microseconds = Microseconds(1000);
    /// Longest pulse: 2000 µs.
    pub const MAX_PULSE: Microseconds = Microseconds(2000);
    /// 50 Hz servo frame: 1 000 000 µs / 50 = 20 000 µs.
    pub const PERIOD_50HZ: Microseconds = Microseconds(1_000_000 / 50);
}

impl ServoCalibration {
    /// A typical hobby servo on `axis`: 1500 µs neutral, 11 111 ns/° (1000 µs per
    /// 90°), normal direction, pulses 1000..2000 µs (±45°), limits = the axis'
    /// anatomical limits (Table 1; the widest, yaw +32°, needs 1500 + 32 · 11.111
    /// = 1856 µs, inside the pulse range).
    #[must_use]
    pub const fn hobby(axis: Axis) -> Self {
        Self {
            neutral: defaults::NEUTRAL,
            per_degree: defaults::PER_DEGREE,
            direction: Direction::Normal,
            min_pulse: defaults::MIN_PULSE,
            max_pulse: defaults::MAX_PULSE,
            limits: axis.anatomical_limits(),
        }
    }

    /// The same calibration with the direction `direction`.
    #[must_use]
    pub const fn with_direction(mut self, direction: Direction) -> Self {
        self.direction = direction;
        self
    }

    /// Checks the calibration.
    ///
    /// # Errors
    /// The first problem found, in this order:
    /// [`ServoError::PulseOutsideBounds`], [`ServoError::PulseRangeEmpty`],
    /// [`ServoError::NeutralOutsidePulseRange`], [`ServoError::ZeroPerDegree`],
    /// [`ServoError::LimitsInverted`], [`ServoError::NeutralOutsideLimits`],
    /// [`ServoError::LimitUnreachable`].
    ///
    /// ```
    /// use idle_head_core::servo::{ServoCalibration, ServoError};
    /// use idle_head_core::{Angle, Axis, Microseconds};
    /// let mut cal = ServoCalibration::hobby(Axis::Pitch);
    /// cal.max_pulse = Microseconds(1700); // +20° needs 1722 µs
    /// let err = cal.validate().unwrap_err();
    /// assert_eq!(
    ///     err,
    ///     ServoError::LimitUnreachable {
    ///         angle: Angle::from_degrees(20),
    ///         needed_us: 1722,
    ///         min: Microseconds(1000),
    ///         max: Microseconds(1700),
    ///     }
    /// );
    /// assert_eq!(err.to_string(), "limit +20° needs 1722 µs, outside the pulse range 1000..1700 µs");
    /// ```
    pub const fn validate(&self) -> Result<(), ServoError> {
        if self.min_pulse.0 < bounds::MIN_PULSE.0 || self.min_pulse.0 > bounds::MAX_PULSE.0 {
            return Err(ServoError::PulseOutsideBounds {
                max: false,
                pulse: self.min_pulse,
            });
        }
        if self.max_pulse.0 < bounds::MIN_PULSE.0 || self.max_pulse.0 > bounds::MAX_PULSE.0 {
            return Err(ServoError::PulseOutsideBounds {
                max: true,
                pulse: self.max_pulse,
            });
        }
        if self.min_pulse.0 >= self.max_pulse.0 {
            return Err(ServoError::PulseRangeEmpty {
                min: self.min_pulse,
                max: self.max_pulse,
            });
        }
        if self.neutral.0 < self.min_pulse.0 || self.neutral.0 > self.max_pulse.0 {
            return Err(ServoError::NeutralOutsidePulseRange {
                neutral: self.neutral,
                min: self.min_pulse,
                max: self.max_pulse,
            });
        }
        if self.per_degree.0 == 0 {
            return Err(ServoError::ZeroPerDegree);
        }
        if self.limits.min.millidegrees() > self.limits.max.millidegrees() {
            return Err(ServoError::LimitsInverted {
                limits: self.limits,
            });
        }
        if !self.limits.contains(Angle::ZERO) {
            return Err(ServoError::NeutralOutsideLimits {
                limits: self.limits,
            });
        }
        let ends = [self.limits.min, self.limits.max];
        let mut i = 0;
        while i < ends.len() {
            let angle = ends[i];
            let needed = self.raw_pulse_us(angle);
            if needed < self.min_pulse.0 as i64 || needed > self.max_pulse.0 as i64 {
                return Err(ServoError::LimitUnreachable {
                    angle,
                    needed_us: needed,
                    min: self.min_pulse,
                    max: self.max_pulse,
                });
            }
            i += 1;
        }
        Ok(())
    }

    /// The pulse (shortest, then longest) outside the range most hobby
    /// servos accept ([`bounds::TYPICAL_MIN`]..=[`bounds::TYPICAL_MAX`]),
    /// if the calibration can write one: a valid calibration, but one to
    /// check against the servo's data sheet and end stops.
    ///
    /// ```
    /// use idle_head_core::servo::ServoCalibration;
    /// use idle_head_core::{Axis, Microseconds};
    /// let mut cal = ServoCalibration::hobby(Axis::Yaw);
    /// assert_eq!(cal.unusual(), None);
    /// cal.min_pulse = Microseconds(900);
    /// assert_eq!(cal.unusual(), Some(Microseconds(900)));
    /// ```
    #[must_use]
    pub const fn unusual(&self) -> Option<Microseconds> {
        if self.min_pulse.0 < bounds::TYPICAL_MIN.0 {
            Some(self.min_pulse)
        } else if self.max_pulse.0 > bounds::TYPICAL_MAX.0 {
            Some(self.max_pulse)
        } else {
            None
        }
    }

    /// Fails compilation (in a `const` context) with a message naming the field
    /// if the calibration is invalid; for built-in configurations:
    ///
    /// ```
    /// use idle_head_core::servo::ServoCalibration;
    /// use idle_head_core::Axis;
    /// const CAL: ServoCalibration = ServoCalibration::hobby(Axis::Roll);
    /// const _: () = CAL.assert_valid();
    /// ```
    ///
    /// ```compile_fail
    /// use idle_head_core::servo::ServoCalibration;
    /// use idle_head_core::{Axis, Microseconds};
    /// const CAL: ServoCalibration = {
    ///     let mut c = ServoCalibration::hobby(Axis::Roll);
    ///     c.neutral = Microseconds(2500); // "`neutral` must lie in [`min_pulse`, `max_pulse`]"
    ///     c
    /// };
    /// const _: () = CAL.assert_valid();
    /// ```
    ///
    /// # Panics
    /// If [`validate`](Self::validate) fails (at compile time when used in a `const`).
    pub const fn assert_valid(&self) {
        if let Err(e) = self.validate() {
            panic!("{}", e.message());
        }
    }

    /// The unclamped pulse for `angle`, in µs: `neutral ± angle · per_degree`,
    /// rounded to the nearest µs (halves away from zero, so both directions
    /// are symmetric). Cannot overflow: |angle| < 2^31 m°, `per_degree` < 2^32.
    #[must_use]
    pub const fn raw_pulse_us(&self, angle: Angle) -> i64 {
        // millidegrees · ns/degree = picoseconds; 10^6 ps = 1 µs.
        let ps = angle.millidegrees() as i64 * self.per_degree.0 as i64;
        let us = if ps >= 0 {
            (ps + PS_PER_US / 2) / PS_PER_US
        } else {
            (ps - PS_PER_US / 2) / PS_PER_US
        };
        match self.direction {
            Direction::Normal => self.neutral.0 as i64 + us,
            Direction::Reversed => self.neutral.0 as i64 - us,
        }
    }

    /// The unclamped pulse for `angle`, in picoseconds, exactly:
    /// `neutral · 10⁶ ± angle · per_degree` (m° · ns/° = ps), saturating
    /// at the ends of `i64` (`|angle · per_degree|` < 2⁶³ already).
    #[must_use]
    pub const fn raw_pulse_ps(&self, angle: Angle) -> i64 {
        let ps = angle.millidegrees() as i64 * self.per_degree.0 as i64;
        let neutral = self.neutral.0 as i64 * PS_PER_US;
        match self.direction {
            Direction::Normal => neutral.saturating_add(ps),
            Direction::Reversed => neutral.saturating_sub(ps),
        }
    }

    /// The pulse for `angle` in picoseconds, clamped to `[min_pulse,
    /// max_pulse]`: what the PWM is asked to write, before its counts
    /// round it ([`PwmTiming::duty_ps`]). [`pulse`](Self::pulse) is this
    /// in whole µs.
    ///
    /// ```
    /// use idle_head_core::servo::ServoCalibration;
    /// use idle_head_core::{Angle, Axis};
    /// let cal = ServoCalibration::hobby(Axis::Yaw);
    /// // 16 m° · 11 111 ns/° = 177 776 ps above the 1500 µs neutral.
    /// assert_eq!(cal.pulse_ps(Angle::from_millidegrees(16)), 1_500_177_776);
    /// assert_eq!(cal.pulse_ps(Angle::from_degrees(90)), 2_000_000_000);
    /// ```
    #[must_use]
    pub const fn pulse_ps(&self, angle: Angle) -> u64 {
        let raw = self.raw_pulse_ps(angle);
        let (min, max) = (
            self.min_pulse.0 as i64 * PS_PER_US,
            self.max_pulse.0 as i64 * PS_PER_US,
        );
        if raw <= min {
            min as u64
        } else if raw >= max {
            max as u64
        } else {
            raw as u64
        }
    }

    /// The pulse for `angle`, clamped to `[min_pulse, max_pulse]` (never panics,
    /// even for an invalid calibration: then the result is `min_pulse`).
    #[must_use]
    pub const fn pulse(&self, angle: Angle) -> Microseconds {
        let raw = self.raw_pulse_us(angle);
        if raw <= self.min_pulse.0 as i64 {
            self.min_pulse
        } else if raw >= self.max_pulse.0 as i64 {
            self.max_pulse
        } else {
            Microseconds(raw as u32)
        }
    }

    /// `angle` clamped to the mechanical [`limits`](Self::limits).
    #[must_use]
    pub const fn clamp_angle(&self, angle: Angle) -> Angle {
        angle.clamp_to(self.limits.min, self.limits.max)
    }
}

/// PWM timing shared by the servo channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PwmTiming {
    /// PWM period: the time represented by the channel's maximum duty.
    pub period: Microseconds,
}

impl PwmTiming {
    /// The usual analogue servo timing: 50 Hz, a 20 000 µs period.
    pub const SERVO_50HZ: Self = Self {
        period: defaults::PERIOD_50HZ,
    };

    /// Duty ticks for `pulse` on a channel whose full period is `max_duty`
    /// ticks: `pulse · max_duty / period`, rounded to the nearest tick and
    /// saturated at `max_duty` (also for a zero period).
    ///
    /// ```
    /// use idle_head_core::servo::{Duty, PwmTiming};
    /// use idle_head_core::Microseconds;
    /// let t = PwmTiming::SERVO_50HZ;
    /// assert_eq!(t.duty(Microseconds(1000), 20_000), Duty(1000));
    /// assert_eq!(t.duty(Microseconds(30_000), 20_000), Duty(20_000));
    /// ```
    #[must_use]
    pub const fn duty(&self, pulse: Microseconds, max_duty: u16) -> Duty {
        // < 2^32 · 2^16 + 2^32 < 2^64: no overflow.
        let num = pulse.0 as u64 * max_duty as u64 + self.period.0 as u64 / 2;
        let Some(ticks) = num.checked_div(self.period.0 as u64) else {
            return Duty(max_duty);
        };
        if ticks >= max_duty as u64 {
            Duty(max_duty)
        } else {
            Duty(ticks as u16)
        }
    }

    /// Duty ticks for a pulse of `ps` picoseconds, as [`duty`](Self::duty)
    /// counts a pulse in µs: `⌊(ps · max_duty + ⌊T/2⌋) / T⌋` with the period
    /// `T` in ps, saturated at `max_duty` (also for a zero period). For a
    /// whole-µs pulse it is [`duty`](Self::duty) of it; between whole µs it
    /// keeps the resolution of the PWM's counts (at 200 Hz on the Pico, 80
    /// ns: 62 500 counts per 5000 µs).
    ///
    /// ```
    /// use idle_head_core::servo::{Duty, PwmTiming};
    /// use idle_head_core::Microseconds;
    /// let t = PwmTiming { period: Microseconds(5000) };
    /// assert_eq!(t.duty_ps(1_500_000_000, 62_499), t.duty(Microseconds(1500), 62_499));
    /// // 0.18 µs more: two counts of 80 ns more, where the µs would round it away.
    /// assert_eq!(t.duty_ps(1_500_177_776, 62_499).0, t.duty(Microseconds(1500), 62_499).0 + 2);
    /// ```
    #[must_use]
    pub const fn duty_ps(&self, ps: u64, max_duty: u16) -> Duty {
        let period = self.period.0 as u64 * PS_PER_US as u64;
        if period == 0 {
            return Duty(max_duty);
        }
        // ps · max_duty fits u64 for any pulse up to 2.8 s; wider in u128.
        let ticks = match ps.checked_mul(max_duty as u64) {
            Some(p) if p <= u64::MAX - period / 2 => (p + period / 2) / period,
            _ => ((ps as u128 * max_duty as u128 + (period / 2) as u128) / period as u128) as u64,
        };
        if ticks >= max_duty as u64 {
            Duty(max_duty)
        } else {
            Duty(ticks as u16)
        }
    }
}
