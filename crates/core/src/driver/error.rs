//! Configurations the driver rejects, with the rejected values.

use crate::text::Arg::{Int, Str, Text, Uint};
use crate::text::{self, Describe, display_from_describe};

use crate::axis::Axis;
use crate::servo::{Degrees, ServoError};
use crate::units::{Angle, AngleRange, DegreesPerSecondSquared, Microseconds};

use super::limiter::MAX_LIMIT_MDEG;

/// A configuration rejected by [`DriverConfig::build`](super::DriverConfig::build),
/// [`FrameDriver::set_servo`](super::FrameDriver::set_servo) or
/// [`FrameDriver::set_motion_limits`](super::FrameDriver::set_motion_limits),
/// with the rejected values.
///
/// Its [`Display`](core::fmt::Display) names the servo and the field and gives the
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
    /// `faults.disable_after` is zero ms.
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
                ServoError::PulseOutsideBounds { .. } => {
                    per_axis!(
                        axis,
                        "servos",
                        ".min_pulse",
                        "or `max_pulse` outside 500..=2500 µs"
                    )
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
/// use idle_head_core::driver::DriverConfig;
/// use idle_head_core::servo::NanosPerDegree;
/// use idle_head_core::AngleRange;
/// let mut cfg = DriverConfig::DEFAULT;
/// cfg.servos[0].per_degree = NanosPerDegree(1000); // 1 µs/°: ±400° within 1100..1900 µs
/// cfg.servos[0].limits = AngleRange::degrees(-12, 400);
/// assert_eq!(
///     cfg.build().unwrap_err().to_string(),
///     "pitch servo: limit +400° lies beyond ±360°, the widest range the driver takes"
/// );
/// ```
impl Describe for ConfigError {
    fn describe(&self, out: &mut dyn text::Text) {
        match *self {
            Self::ZeroFramePeriod => out.str("frame_period must be longer than 0 µs"),
            Self::ZeroPwmPeriod => out.str("pwm.period must be longer than 0 µs"),
            Self::ZeroDisableAfter => out.str("faults.disable_after must be at least 1 ms"),
            Self::Servo { axis, error } => {
                out.fill("{} servo: {}", &[Str(axis.name()), Text(&error)])
            }
            Self::PulseLongerThanPeriod {
                axis,
                max_pulse,
                period,
            } => out.fill(
                "{} servo: max_pulse {} µs is longer than the PWM period of {} µs",
                &[
                    Str(axis.name()),
                    Uint(max_pulse.0.into()),
                    Uint(period.0.into()),
                ],
            ),
            Self::LimitOutOfRange { axis, limit } => out.fill(
                "{} servo: limit {} lies beyond ±{}°, the widest range the driver takes",
                &[
                    Str(axis.name()),
                    Text(&Degrees(limit)),
                    Int((MAX_LIMIT_MDEG / 1000).into()),
                ],
            ),
            Self::NeutralPoseOutsideLimits { axis, pose, limits } => out.fill(
                "{}: neutral_pose {} lies outside the servo's limits {}..{}",
                &[
                    Str(axis.name()),
                    Text(&Degrees(pose)),
                    Text(&Degrees(limits.min)),
                    Text(&Degrees(limits.max)),
                ],
            ),
            Self::ZeroSpeedLimit { axis } => out.fill(
                "{}: motion max_speed must be at least 1 °/s",
                &[Str(axis.name())],
            ),
            Self::AccelBelowResolution {
                axis,
                max_accel,
                frame_period,
            } => out.fill(
                "{}: motion max_accel {} °/s² is below {} °/s², the least the driver resolves \
                 (1 µ° per frame²) at frames of {} µs",
                &[
                    Str(axis.name()),
                    Uint(max_accel.0.into()),
                    Uint(least_accel(frame_period)),
                    Uint(frame_period.0.into()),
                ],
            ),
        };
    }
}

/// ```
/// use idle_head_core::servo::{ServoCalibration, ServoError};
/// use idle_head_core::{Axis, Microseconds};
/// let mut cal = ServoCalibration::hobby(Axis::Roll);
/// cal.min_pulse = Microseconds(2500);
/// let err = cal.validate().unwrap_err();
/// assert_eq!(err.to_string(), "min_pulse 2500 µs must be below max_pulse 2000 µs");
/// ```
impl Describe for ServoError {
    fn describe(&self, out: &mut dyn text::Text) {
        match *self {
            Self::PulseRangeEmpty { min, max } => out.fill(
                "min_pulse {} µs must be below max_pulse {} µs",
                &[Uint(min.0.into()), Uint(max.0.into())],
            ),
            Self::NeutralOutsidePulseRange { neutral, min, max } => out.fill(
                "neutral {} µs lies outside the pulse range {}..{} µs",
                &[
                    Uint(neutral.0.into()),
                    Uint(min.0.into()),
                    Uint(max.0.into()),
                ],
            ),
            Self::ZeroPerDegree => out.str("per_degree must be above 0 ns/°"),
            Self::PulseOutsideBounds { max, pulse } => out.fill(
                "{} {} µs is outside {}..={} µs, the pulses no servo setting may pass",
                &[
                    Str(if max { "max_pulse" } else { "min_pulse" }),
                    Uint(pulse.0.into()),
                    Uint(crate::servo::bounds::MIN_PULSE.0.into()),
                    Uint(crate::servo::bounds::MAX_PULSE.0.into()),
                ],
            ),
            Self::LimitsInverted { limits } => out.fill(
                "limits {}..{}: the lower limit lies above the upper one",
                &[Text(&Degrees(limits.min)), Text(&Degrees(limits.max))],
            ),
            Self::NeutralOutsideLimits { limits } => out.fill(
                "limits {}..{} must contain 0°, the neutral angle the servo starts at",
                &[Text(&Degrees(limits.min)), Text(&Degrees(limits.max))],
            ),
            Self::LimitUnreachable {
                angle,
                needed_us,
                min,
                max,
            } => out.fill(
                "limit {} needs {} µs, outside the pulse range {}..{} µs",
                &[
                    Text(&Degrees(angle)),
                    Int(needed_us),
                    Uint(min.0.into()),
                    Uint(max.0.into()),
                ],
            ),
        };
    }
}

/// `+20°`, `-12.5°`, `0°`: the sign and up to three decimals.
impl Describe for Degrees {
    fn describe(&self, out: &mut dyn text::Text) {
        let m = self.0.millidegrees();
        let sign = match m {
            0 => "",
            ..0 => "-",
            _ => "+",
        };
        out.str(sign).milli(m.unsigned_abs().into()).str("°");
    }
}

display_from_describe!(ConfigError);

impl core::error::Error for ConfigError {}

/// The smallest whole °/s² that is at least 1 µ° per frame² at frames of
/// `frame_period`: ⌈10⁶/f²⌉ with f in µs (see `slew_params`).
fn least_accel(frame_period: Microseconds) -> u64 {
    let f = u64::from(frame_period.0).max(1);
    1_000_000_u64.div_ceil(f.saturating_mul(f))
}

/// Why the servos did not change their period
/// ([`FrameDriver::set_pwm_period`](super::FrameDriver::set_pwm_period)):
/// nothing changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RateError {
    /// The configuration does not hold at that period.
    Config(ConfigError),
    /// A servo's output cannot run at that period exactly.
    Output {
        /// The servo's axis.
        axis: Axis,
        /// The period it refused.
        period: Microseconds,
    },
}

impl Describe for RateError {
    fn describe(&self, out: &mut dyn text::Text) {
        match *self {
            Self::Config(e) => e.describe(out),
            Self::Output { axis, period } => {
                out.fill(
                    "the {} servo's output cannot run at {} µs",
                    &[Str(axis.name()), Uint(period.0.into())],
                );
            }
        }
    }
}

display_from_describe!(RateError);

impl core::error::Error for RateError {}
