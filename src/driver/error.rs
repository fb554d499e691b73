//! Configurations the driver rejects, with the rejected values.

use core::fmt;

use crate::axis::Axis;
use crate::servo::{Degrees, ServoError};
use crate::units::{Angle, AngleRange, Microseconds};

use super::DegreesPerSecondSquared;
use super::limiter::MAX_LIMIT_MDEG;

/// A configuration rejected by [`DriverConfig::build`](super::DriverConfig::build),
/// [`FrameDriver::set_servo`](super::FrameDriver::set_servo) or
/// [`FrameDriver::set_motion_limits`](super::FrameDriver::set_motion_limits),
/// with the rejected values.
///
/// Its [`Display`](fmt::Display) names the servo and the field and gives the
/// rejected value and what is allowed, in µs and degrees;
/// [`message`](Self::message) is a fixed text for `const` checks and logs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ConfigError {
    /// `frame_period` is zero.
    ZeroFramePeriod,
    /// `pwm.period` is zero.
    ZeroPwmPeriod,
    /// `faults.disable_after` is zero.
    ZeroDisableAfter,
    /// A servo calibration is invalid.
    Servo {
        /// The servo's axis.
        axis: Axis,
        /// What is wrong with it.
        error: ServoError,
    },
    /// A servo's `max_pulse` is longer than the PWM period.
    PulseLongerThanPeriod {
        /// The servo's axis.
        axis: Axis,
        /// The rejected maximum pulse.
        max_pulse: Microseconds,
        /// The PWM period.
        period: Microseconds,
    },
    /// A servo's angle limit lies beyond ±360°, the widest the driver takes.
    LimitOutOfRange {
        /// The servo's axis.
        axis: Axis,
        /// The rejected limit.
        limit: Angle,
    },
    /// The neutral pose lies outside the axis' mechanical limits.
    NeutralPoseOutsideLimits {
        /// The axis.
        axis: Axis,
        /// The rejected pose angle.
        pose: Angle,
        /// The servo's limits.
        limits: AngleRange,
    },
    /// An axis' speed limit is zero: it could never move.
    ZeroSpeedLimit {
        /// The axis.
        axis: Axis,
    },
    /// An axis' acceleration limit rounds to zero µ° per frame² at this frame period.
    AccelBelowResolution {
        /// The axis.
        axis: Axis,
        /// The rejected acceleration limit.
        max_accel: DegreesPerSecondSquared,
        /// The frame period.
        frame_period: Microseconds,
    },
}

impl ConfigError {
    /// A one-line description naming the offending field, for logs and build errors.
    #[must_use]
    pub const fn message(&self) -> &'static str {
        /// `driver config: `<field>[<axis>]<sub>` <what>` as a literal per axis.
        macro_rules! per_axis {
            ($axis:expr, $field:literal, $sub:literal, $what:literal) => {
                match $axis {
                    Axis::Pitch => {
                        concat!("driver config: `", $field, "[pitch]", $sub, "` ", $what)
                    }
                    Axis::Roll => concat!("driver config: `", $field, "[roll]", $sub, "` ", $what),
                    Axis::Yaw => concat!("driver config: `", $field, "[yaw]", $sub, "` ", $what),
                }
            };
        }
        match self {
            Self::ZeroFramePeriod => "driver config: `frame_period` must not be zero",
            Self::ZeroPwmPeriod => "driver config: `pwm.period` must not be zero",
            Self::ZeroDisableAfter => "driver config: `faults.disable_after` must not be zero",
            Self::Servo { axis, error } => match error {
                ServoError::PulseRangeEmpty { .. } => {
                    per_axis!(axis, "servos", ".min_pulse", "must be below `max_pulse`")
                }
                ServoError::NeutralOutsidePulseRange { .. } => {
                    per_axis!(
                        axis,
                        "servos",
                        ".neutral",
                        "must lie in [`min_pulse`, `max_pulse`]"
                    )
                }
                ServoError::ZeroPerDegree => {
                    per_axis!(axis, "servos", ".per_degree", "must not be zero")
                }
                ServoError::LimitsInverted { .. } => {
                    per_axis!(axis, "servos", ".limits", "is inverted (min > max)")
                }
                ServoError::NeutralOutsideLimits { .. } => {
                    per_axis!(
                        axis,
                        "servos",
                        ".limits",
                        "must contain 0° (the neutral angle)"
                    )
                }
                ServoError::LimitUnreachable { .. } => per_axis!(
                    axis,
                    "servos",
                    ".limits",
                    "needs a pulse outside [`min_pulse`, `max_pulse`]"
                ),
            },
            Self::PulseLongerThanPeriod { axis, .. } => {
                per_axis!(axis, "servos", ".max_pulse", "is longer than `pwm.period`")
            }
            Self::LimitOutOfRange { axis, .. } => {
                per_axis!(axis, "servos", ".limits", "reaches beyond ±360°")
            }
            Self::NeutralPoseOutsideLimits { axis, .. } => {
                per_axis!(
                    axis,
                    "neutral_pose",
                    "",
                    "lies outside the servo's `limits`"
                )
            }
            Self::ZeroSpeedLimit { axis } => {
                per_axis!(axis, "motion", ".max_speed", "must not be zero")
            }
            Self::AccelBelowResolution { axis, .. } => per_axis!(
                axis,
                "motion",
                ".max_accel",
                "is below 1 µ° per frame² at this `frame_period`"
            ),
        }
    }
}

/// ```
/// use idle_head::driver::DriverConfig;
/// use idle_head::servo::NanosPerDegree;
/// use idle_head::AngleRange;
/// let mut cfg = DriverConfig::DEFAULT;
/// cfg.servos[0].per_degree = NanosPerDegree(1000); // 1 µs/°: ±400° within 1100..1900 µs
/// cfg.servos[0].limits = AngleRange::degrees(-12, 400);
/// assert_eq!(
///     cfg.build().unwrap_err().to_string(),
///     "pitch servo: limit +400° lies beyond ±360°, the widest range the driver takes"
/// );
/// ```
impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::ZeroFramePeriod => f.write_str("frame_period must be longer than 0 µs"),
            Self::ZeroPwmPeriod => f.write_str("pwm.period must be longer than 0 µs"),
            Self::ZeroDisableAfter => f.write_str("faults.disable_after must be at least 1 frame"),
            Self::Servo { axis, error } => write!(f, "{} servo: {error}", axis.name()),
            Self::PulseLongerThanPeriod {
                axis,
                max_pulse,
                period,
            } => write!(
                f,
                "{} servo: max_pulse {} µs is longer than the PWM period of {} µs",
                axis.name(),
                max_pulse.0,
                period.0
            ),
            Self::LimitOutOfRange { axis, limit } => write!(
                f,
                "{} servo: limit {} lies beyond ±{}°, the widest range the driver takes",
                axis.name(),
                Degrees(limit),
                MAX_LIMIT_MDEG / 1000
            ),
            Self::NeutralPoseOutsideLimits { axis, pose, limits } => write!(
                f,
                "{}: neutral_pose {} lies outside the servo's limits {}..{}",
                axis.name(),
                Degrees(pose),
                Degrees(limits.min),
                Degrees(limits.max)
            ),
            Self::ZeroSpeedLimit { axis } => write!(
                f,
                "{}: motion max_speed must be at least 1 °/s",
                axis.name()
            ),
            Self::AccelBelowResolution {
                axis,
                max_accel,
                frame_period,
            } => write!(
                f,
                "{}: motion max_accel {} °/s² is below {} °/s², the least the driver resolves \
                 (1 µ° per frame²) at frames of {} µs",
                axis.name(),
                max_accel.0,
                least_accel(frame_period),
                frame_period.0
            ),
        }
    }
}

impl core::error::Error for ConfigError {}

/// The smallest whole °/s² that is at least 1 µ° per frame² at frames of
/// `frame_period`: ⌈10⁶/f²⌉ with f in µs (see `slew_params`).
fn least_accel(frame_period: Microseconds) -> u64 {
    let f = u64::from(frame_period.0).max(1);
    1_000_000_u64.div_ceil(f.saturating_mul(f))
}
