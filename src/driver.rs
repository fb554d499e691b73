//! The frame driver: loop offsets in, three servo duties out, safely.
//!
//! Per frame and per servo (pitch, roll, yaw):
//!
//! 1. the trajectory offset is scaled by the fade envelope (smoothstep fade-in
//!    after [`FrameDriver::start`], fade-out after [`FrameDriver::request_stop`]);
//! 2. added to the neutral pose and clamped to the axis' mechanical limits;
//! 3. followed within the axis' speed and acceleration limits;
//! 4. converted to a pulse (clamped to the servo's pulse limits) and duty ticks;
//! 5. written; a write error is counted and reported, the other servos carry on
//!    and the servo is written again next frame, its limiter continuing from
//!    the last pulse it actually received; a servo that fails
//!    [`FaultPolicy::disable_after`] frames in a row gets duty 0 once (no
//!    pulses: it goes limp) and is never written again.
//!
//! The first pulse any servo receives is its neutral pulse (0°).
//!
//! Configuration is in physical units ([`DriverConfig`]); [`DriverConfig::build`]
//! validates it into the integer [`DriverParams`] the frame path uses.
//! [`FrameClock`] keeps the frame deadlines and skips late frames.

mod clock;
mod envelope;
mod limiter;

pub use clock::{FrameClock, FrameTick, ZeroPeriod};

use embedded_hal::pwm::{Error as _, ErrorKind, SetDutyCycle};

use crate::axis::Axis;
use crate::servo::{Duty, PwmTiming, ServoCalibration, ServoError};
use crate::units::{Angle, Microseconds, Millis};
use envelope::{Envelope, UNITY};
use limiter::{Slew, SlewParams};

/// Angular speed in whole degrees per second.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DegreesPerSecond(pub u32);

/// Angular acceleration in whole degrees per second squared.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DegreesPerSecondSquared(pub u32);

/// Speed and acceleration limits of one axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotionLimits {
    /// Largest speed of the commanded angle.
    pub max_speed: DegreesPerSecond,
    /// Largest acceleration of the commanded angle.
    pub max_accel: DegreesPerSecondSquared,
}

impl MotionLimits {
    /// 60 °/s and 600 °/s²: well above the idle motion, well below a hobby
    /// servo's own ~500 °/s (0.12 s per 60°), so a broken trajectory or a jump
    /// in the configuration moves the head calmly.
    ///
    /// Measured on the Table 2 loops (N = 900, frames of 20 ms, second
    /// differences of the m°-quantised frames): at 30 s per loop at most
    /// 8.1 °/s and 20 °/s²; at 18 s, 13.5 °/s and 50 °/s²; even at 9 s, 27 °/s
    /// and 200 °/s². The host tests check that the limiter leaves the loop
    /// exactly as played.
    ///
    /// At 50 Hz: 60 °/s · 0.02 s = 1.2° per frame; 600 °/s² · (0.02 s)² =
    /// 0.24° per frame per frame; full speed is reached in 60/600 = 0.1 s.
    pub const DEFAULT: Self = Self {
        max_speed: DegreesPerSecond(60),
        max_accel: DegreesPerSecondSquared(600),
    };
}

/// What to do about PWM write errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultPolicy {
    /// Consecutive failed frames after which a servo is switched off (≥ 1).
    pub disable_after: u16,
    /// Shortest time between two fault log suggestions ([`FrameReport::should_log`]).
    pub log_interval: Millis,
}

impl FaultPolicy {
    /// Switch a servo off after 25 failed frames in a row (25 · 20 ms = 0.5 s at
    /// 50 Hz: long enough to ride out a glitch, short enough that a stuck
    /// channel does not hold the servo at a stale pulse); log at most once a second.
    pub const DEFAULT: Self = Self {
        disable_after: 25,
        log_interval: Millis(1000),
    };
}

/// Everything the frame driver needs, in physical units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverConfig {
    /// Time between frames (calls to [`FrameDriver::write_frame`]).
    pub frame_period: Microseconds,
    /// PWM period of the servo channels.
    pub pwm: PwmTiming,
    /// Calibration per servo, `[pitch, roll, yaw]`.
    pub servos: [ServoCalibration; 3],
    /// Rest pose the trajectory offsets are added to, `[pitch, roll, yaw]`.
    pub neutral_pose: [Angle; 3],
    /// Speed and acceleration limits, `[pitch, roll, yaw]`.
    pub motion: [MotionLimits; 3],
    /// Fade-in (after start) and fade-out (after a stop request) time.
    pub fade: Millis,
    /// PWM error handling.
    pub faults: FaultPolicy,
}

impl DriverConfig {
    /// 50 Hz frames and PWM, hobby servos on the anatomical limits, neutral pose
    /// 0°, [`MotionLimits::DEFAULT`], a 2 s fade, [`FaultPolicy::DEFAULT`].
    pub const DEFAULT: Self = Self {
        frame_period: crate::servo::defaults::PERIOD_50HZ,
        pwm: PwmTiming::SERVO_50HZ,
        servos: [
            ServoCalibration::hobby(Axis::Pitch),
            ServoCalibration::hobby(Axis::Roll),
            ServoCalibration::hobby(Axis::Yaw),
        ],
        neutral_pose: [Angle::ZERO; 3],
        motion: [MotionLimits::DEFAULT; 3],
        fade: Millis(2000),
        faults: FaultPolicy::DEFAULT,
    };

    /// Checks the configuration.
    ///
    /// # Errors
    /// The first problem found, as a [`ConfigError`].
    pub const fn validate(&self) -> Result<(), ConfigError> {
        match self.build() {
            Ok(_) => Ok(()),
            Err(e) => Err(e),
        }
    }

    /// Fails compilation (in a `const` context) with a message naming the field
    /// if the configuration is invalid.
    ///
    /// ```
    /// use idle_head::driver::DriverConfig;
    /// const _: () = DriverConfig::DEFAULT.assert_valid();
    /// ```
    ///
    /// A wrong one fails the build ("driver config: `servos[roll].min_pulse`
    /// must be below `max_pulse`"):
    ///
    /// ```compile_fail
    /// use idle_head::driver::DriverConfig;
    /// use idle_head::Microseconds;
    /// const CFG: DriverConfig = {
    ///     let mut c = DriverConfig::DEFAULT;
    ///     c.servos[1].min_pulse = Microseconds(2500);
    ///     c
    /// };
    /// const _: () = CFG.assert_valid();
    /// ```
    ///
    /// # Panics
    /// If [`validate`](Self::validate) fails (at compile time when used in a `const`).
    pub const fn assert_valid(&self) {
        if let Err(e) = self.build() {
            panic!("{}", e.message());
        }
    }

    /// Validates the configuration into the integer parameters of the frame path.
    ///
    /// # Errors
    /// The first problem found, as a [`ConfigError`].
    ///
    /// ```
    /// use idle_head::driver::{ConfigError, DriverConfig};
    /// use idle_head::servo::ServoError;
    /// use idle_head::{Axis, Microseconds};
    /// let mut cfg = DriverConfig::DEFAULT;
    /// cfg.servos[1].min_pulse = Microseconds(2000);
    /// let err = cfg.build().unwrap_err();
    /// assert!(matches!(
    ///     err,
    ///     ConfigError::Servo { axis: Axis::Roll, error: ServoError::PulseRangeEmpty { .. } }
    /// ));
    /// ```
    pub const fn build(&self) -> Result<DriverParams, ConfigError> {
        /// Cap of the per-frame limits (µ°): far beyond any servo, small enough
        /// that the limiter's sums stay far from i64 overflow.
        const CAP: u128 = 1 << 48;
        const US_PER_S: u128 = 1_000_000;

        let frame_us = self.frame_period.0;
        if frame_us == 0 {
            return Err(ConfigError::ZeroFramePeriod);
        }
        if self.pwm.period.0 == 0 {
            return Err(ConfigError::ZeroPwmPeriod);
        }
        if self.faults.disable_after == 0 {
            return Err(ConfigError::ZeroDisableAfter);
        }
        let mut slew = [SlewParams {
            max_step: 0,
            max_accel: 0,
            lo: 0,
            hi: 0,
        }; 3];
        let mut i = 0;
        while i < 3 {
            let axis = Axis::ALL[i];
            let cal = &self.servos[i];
            if let Err(error) = cal.validate() {
                return Err(ConfigError::Servo { axis, error });
            }
            if cal.max_pulse.0 > self.pwm.period.0 {
                return Err(ConfigError::PulseLongerThanPeriod {
                    axis,
                    max_pulse: cal.max_pulse,
                });
            }
            let pose = self.neutral_pose[i];
            if !cal.limits.contains(pose) {
                return Err(ConfigError::NeutralPoseOutsideLimits { axis, pose });
            }
            let m = &self.motion[i];
            // deg/s · 10^6 µ°/° · frame_us / 10^6 µs/s = µ° per frame.
            let step = m.max_speed.0 as u128 * frame_us as u128;
            // deg/s² · 10^6 µ°/° · (frame_us / 10^6)² = µ° per frame².
            let accel = m.max_accel.0 as u128 * frame_us as u128 * frame_us as u128 / US_PER_S;
            if step == 0 {
                return Err(ConfigError::ZeroSpeedLimit { axis });
            }
            if accel == 0 {
                return Err(ConfigError::AccelBelowResolution { axis });
            }
            slew[i] = SlewParams {
                max_step: (if step > CAP { CAP } else { step }) as i64,
                max_accel: (if accel > CAP { CAP } else { accel }) as i64,
                lo: cal.limits.min.millidegrees() as i64 * 1000,
                hi: cal.limits.max.millidegrees() as i64 * 1000,
            };
            i += 1;
        }
        Ok(DriverParams {
            config: *self,
            slew,
            fade_frames: frames_in(self.fade.0 as u64 * 1000, frame_us),
            log_frames: frames_in(self.faults.log_interval.0 as u64 * 1000, frame_us),
        })
    }
}

// The built-in configuration must be valid: a mistake fails the build.
const _: () = DriverConfig::DEFAULT.assert_valid();

/// Whole frames in `us` microseconds, rounded up, saturating at `u32::MAX`.
const fn frames_in(us: u64, frame_us: u32) -> u32 {
    let f = us.div_ceil(frame_us as u64);
    if f > u32::MAX as u64 {
        u32::MAX
    } else {
        f as u32
    }
}

/// A configuration rejected by [`DriverConfig::build`], with the rejected values.
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
    },
    /// The neutral pose lies outside the axis' mechanical limits.
    NeutralPoseOutsideLimits {
        /// The axis.
        axis: Axis,
        /// The rejected pose angle.
        pose: Angle,
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
            Self::AccelBelowResolution { axis } => per_axis!(
                axis,
                "motion",
                ".max_accel",
                "is below 1 µ° per frame² at this `frame_period`"
            ),
        }
    }
}

/// A validated [`DriverConfig`] in the integer form the frame path uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverParams {
    config: DriverConfig,
    slew: [SlewParams; 3],
    fade_frames: u32,
    log_frames: u32,
}

impl DriverParams {
    /// The configuration these parameters were built from.
    #[must_use]
    pub const fn config(&self) -> &DriverConfig {
        &self.config
    }

    /// Frames of the fade-in and fade-out.
    #[must_use]
    pub const fn fade_frames(&self) -> u32 {
        self.fade_frames
    }

    /// Largest change of the commanded angle of `axis` from one frame to the
    /// next (the speed limit per frame, rounded up to whole millidegrees).
    #[must_use]
    pub const fn max_step(&self, axis: Axis) -> Angle {
        // max_step ∈ [1, 2^48]: the quotient fits i32 for any sane limit.
        let s = self.slew[axis.index()].max_step as u64;
        let m = s.div_ceil(1000);
        Angle::from_millidegrees(if m > i32::MAX as u64 {
            i32::MAX
        } else {
            m as i32
        })
    }
}

/// What happened to one servo in a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outcome {
    /// The duty was written.
    Written,
    /// The write failed; the servo is written again next frame.
    Failed(ErrorKind),
    /// The write failed once too often: the servo was switched off this frame.
    Disabled(ErrorKind),
    /// The servo was switched off earlier and is not written any more.
    Off,
}

/// One servo's part of a [`FrameReport`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoReport {
    /// Commanded angle after fade, limits and clamping.
    pub angle: Angle,
    /// Pulse for that angle (clamped to the servo's pulse limits).
    pub pulse: Microseconds,
    /// Duty ticks for that pulse (the value written, unless `outcome` says otherwise).
    pub duty: Duty,
    /// Whether it was written.
    pub outcome: Outcome,
}

/// What [`FrameDriver::start`] or [`FrameDriver::write_frame`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameReport {
    /// The driver's frame count (0 for the start frame).
    pub frame: u64,
    /// Per servo, `[pitch, roll, yaw]`.
    pub servos: [ServoReport; 3],
    /// Servos written successfully.
    pub written: u8,
    /// Servos whose write failed (including the ones disabled this frame).
    pub failed: u8,
    /// Servos switched off this frame.
    pub disabled: u8,
    /// Whether to log this frame's faults: set for a newly disabled servo and
    /// otherwise at most once per [`FaultPolicy::log_interval`].
    pub should_log: bool,
    /// Write errors since the last frame with `should_log` (including this frame's).
    pub unlogged_faults: u32,
}

/// Running totals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverStats {
    /// Frames issued (start frame included).
    pub frames: u64,
    /// Write errors per servo.
    pub faults: [u32; 3],
    /// Whether each servo has been switched off.
    pub disabled: [bool; 3],
}

/// Per-servo runtime state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct ServoState {
    slew: Slew,
    consecutive_failures: u16,
    disabled: bool,
}

/// Drives three servos frame by frame; see the [module docs](self).
///
/// ```
/// use embedded_hal::pwm::{ErrorType, SetDutyCycle};
/// use idle_head::driver::{DriverConfig, FrameDriver};
/// use idle_head::servo::Duty;
/// use idle_head::Angle;
///
/// /// A PWM channel that remembers its duty (20 000 ticks = 20 ms: 1 tick per µs).
/// struct Channel(u16);
/// impl ErrorType for Channel {
///     type Error = core::convert::Infallible;
/// }
/// impl SetDutyCycle for Channel {
///     fn max_duty_cycle(&self) -> u16 { 20_000 }
///     fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
///         self.0 = duty;
///         Ok(())
///     }
/// }
///
/// const PARAMS: idle_head::driver::DriverParams = match DriverConfig::DEFAULT.build() {
///     Ok(p) => p,
///     Err(e) => panic!("{}", e.message()),
/// };
/// let mut driver = FrameDriver::new([Channel(0), Channel(0), Channel(0)], PARAMS);
/// let report = driver.start();
/// assert_eq!(report.servos[0].duty, Duty(1500)); // neutral first
/// for _ in 0..200 {
///     driver.write_frame([Angle::from_degrees(9); 3]); // fade in (2 s = 100 frames)
/// }
/// assert_eq!(driver.release()[0].0, 1600); // 9° · 11.111 µs/° = 100 µs
/// ```
#[derive(Debug)]
pub struct FrameDriver<P> {
    channels: [P; 3],
    params: DriverParams,
    max_duty: [u16; 3],
    servos: [ServoState; 3],
    envelope: Envelope,
    /// The last report; `None` until started.
    last: Option<FrameReport>,
    frame: u64,
    stats: DriverStats,
    last_log: Option<u64>,
    unlogged: u32,
}

impl<P: SetDutyCycle> FrameDriver<P> {
    /// A driver for `channels` (`[pitch, roll, yaw]`). Reads each channel's
    /// maximum duty once (pitch, roll, yaw), so the PWM period must be set up
    /// before and not change afterwards; writes nothing until [`start`](Self::start).
    pub fn new(channels: [P; 3], params: DriverParams) -> Self {
        let max_duty = [
            channels[0].max_duty_cycle(),
            channels[1].max_duty_cycle(),
            channels[2].max_duty_cycle(),
        ];
        Self {
            channels,
            params,
            max_duty,
            servos: [ServoState::default(); 3],
            envelope: Envelope::new(params.fade_frames),
            last: None,
            frame: 0,
            stats: DriverStats::default(),
            last_log: None,
            unlogged: 0,
        }
    }

    /// Writes every servo's neutral pulse (0°): the first pulse a servo ever
    /// receives. The idle motion then fades in from the next frame on.
    /// Once started, it writes nothing and returns the last frame's report.
    pub fn start(&mut self) -> FrameReport {
        if let Some(last) = self.last {
            return last;
        }
        let mut report = self.empty_report();
        for (i, slot) in report.servos.iter_mut().enumerate() {
            *slot = self.write_servo(i, Angle::ZERO);
        }
        self.finish(report)
    }

    /// Writes one frame of `offsets` (`[pitch, roll, yaw]`, relative to the
    /// neutral pose); see the [module docs](self) for what happens to them.
    /// Before [`start`](Self::start), it starts instead (ignoring `offsets`).
    pub fn write_frame(&mut self, offsets: [Angle; 3]) -> FrameReport {
        if self.last.is_none() {
            return self.start();
        }
        let gain = self.envelope.gain();
        self.envelope.advance();
        let mut report = self.empty_report();
        let poses = self.params.config.neutral_pose;
        let slews = self.params.slew;
        let inputs = offsets.iter().zip(poses.iter()).zip(slews.iter());
        for (i, (((&offset, &pose), slew), slot)) in
            inputs.zip(report.servos.iter_mut()).enumerate()
        {
            let target = pose.saturating_add(scale(offset, gain));
            let Some(state) = self.servos.get_mut(i) else {
                continue;
            };
            let before = state.slew;
            let angle = state.slew.step(target, slew);
            *slot = self.write_servo(i, angle);
            if slot.outcome != Outcome::Written {
                // The servo still holds the last pulse written: continue from
                // there, so that the next pulse it gets is within the limits.
                if let Some(state) = self.servos.get_mut(i) {
                    state.slew = before;
                }
            }
        }
        self.finish(report)
    }

    /// Fades the motion out to the neutral pose (then holds it).
    pub fn request_stop(&mut self) {
        self.envelope.set_stopping(true);
    }

    /// Fades the motion in again after [`request_stop`](Self::request_stop).
    pub fn resume(&mut self) {
        self.envelope.set_stopping(false);
    }

    /// Whether a stop was requested and the fade-out has finished.
    #[must_use]
    pub fn is_stopped(&self) -> bool {
        self.envelope.is_stopped()
    }

    /// Whether a stop was requested.
    #[must_use]
    pub fn is_stopping(&self) -> bool {
        self.envelope.is_stopping()
    }

    /// Running totals.
    #[must_use]
    pub fn stats(&self) -> &DriverStats {
        &self.stats
    }

    /// The parameters in use.
    #[must_use]
    pub fn params(&self) -> &DriverParams {
        &self.params
    }

    /// The PWM channels, `[pitch, roll, yaw]`.
    pub fn channels_mut(&mut self) -> &mut [P; 3] {
        &mut self.channels
    }

    /// Gives the PWM channels back.
    pub fn release(self) -> [P; 3] {
        self.channels
    }

    fn empty_report(&self) -> FrameReport {
        let idle = ServoReport {
            angle: Angle::ZERO,
            pulse: Microseconds(0),
            duty: Duty(0),
            outcome: Outcome::Off,
        };
        FrameReport {
            frame: self.frame,
            servos: [idle; 3],
            written: 0,
            failed: 0,
            disabled: 0,
            should_log: false,
            unlogged_faults: 0,
        }
    }

    /// Clamps, converts and writes servo `i`'s angle; counts the outcome.
    fn write_servo(&mut self, i: usize, angle: Angle) -> ServoReport {
        let (Some(cal), Some(&max_duty), Some(state), Some(channel)) = (
            self.params.config.servos.get(i),
            self.max_duty.get(i),
            self.servos.get_mut(i),
            self.channels.get_mut(i),
        ) else {
            return ServoReport {
                angle,
                pulse: Microseconds(0),
                duty: Duty(0),
                outcome: Outcome::Off,
            };
        };
        let angle = cal.clamp_angle(angle);
        let pulse = cal.pulse(angle);
        let duty = self.params.config.pwm.duty(pulse, max_duty);
        let outcome = if state.disabled {
            Outcome::Off
        } else {
            match channel.set_duty_cycle(duty.0) {
                Ok(()) => {
                    state.consecutive_failures = 0;
                    Outcome::Written
                }
                Err(e) => {
                    let kind = e.kind();
                    state.consecutive_failures = state.consecutive_failures.saturating_add(1);
                    if let Some(f) = self.stats.faults.get_mut(i) {
                        *f = f.saturating_add(1);
                    }
                    if state.consecutive_failures >= self.params.config.faults.disable_after {
                        // Best effort: no pulses, the servo goes limp. Nothing
                        // more can be done if this write fails too.
                        let _ = channel.set_duty_cycle(0);
                        state.disabled = true;
                        if let Some(d) = self.stats.disabled.get_mut(i) {
                            *d = true;
                        }
                        Outcome::Disabled(kind)
                    } else {
                        Outcome::Failed(kind)
                    }
                }
            }
        };
        ServoReport {
            angle,
            pulse,
            duty,
            outcome,
        }
    }

    /// Totals, fault log throttling and the frame counter.
    fn finish(&mut self, mut report: FrameReport) -> FrameReport {
        for s in &report.servos {
            match s.outcome {
                Outcome::Written => report.written += 1,
                Outcome::Failed(_) => report.failed += 1,
                Outcome::Disabled(_) => {
                    report.failed += 1;
                    report.disabled += 1;
                }
                Outcome::Off => {}
            }
        }
        self.unlogged = self.unlogged.saturating_add(report.failed as u32);
        if report.failed > 0 {
            let due = match self.last_log {
                None => true,
                Some(last) => self.frame.saturating_sub(last) >= self.params.log_frames as u64,
            };
            if due || report.disabled > 0 {
                report.should_log = true;
                report.unlogged_faults = self.unlogged;
                self.unlogged = 0;
                self.last_log = Some(self.frame);
            }
        }
        if !report.should_log {
            report.unlogged_faults = self.unlogged;
        }
        self.frame = self.frame.saturating_add(1);
        self.stats.frames = self.stats.frames.saturating_add(1);
        self.last = Some(report);
        report
    }
}

/// `offset · gain`, gain in Q16 (`0..=65 536`), rounded to the nearest m°.
fn scale(offset: Angle, gain: u32) -> Angle {
    let gain = gain.min(UNITY) as i64;
    // |offset| < 2^31, gain ≤ 2^16: product < 2^47.
    let v = (offset.millidegrees() as i64 * gain + (1 << 15)) >> 16;
    // |v| ≤ |offset|: fits i32.
    Angle::from_millidegrees(v as i32)
}
