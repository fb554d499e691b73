//! The driver's configuration in physical units and its validation into the
//! integer parameters of the frame path.

use crate::axis::Axis;
use crate::servo::{PwmTiming, ServoCalibration};
use crate::units::{
    Angle, AngleRange, DegreesPerSecond, DegreesPerSecondSquared, Microseconds, Millis,
};

use super::ConfigError;
use super::limiter::{MAX_LIMIT_MDEG, SlewParams, SlewRates};

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
    /// How long a servo's writes may fail in a row before it is switched
    /// off (at least 1 ms; counted in whole frames, at least one:
    /// [`DriverParams::disable_frames`]).
    pub disable_after: Millis,
    /// Shortest time between two fault log suggestions
    /// ([`FrameReport::should_log`](super::FrameReport::should_log)).
    pub log_interval: Millis,
}

impl FaultPolicy {
    /// Switch a servo off after 0.5 s of failed writes in a row (25 frames
    /// at 50 Hz: long enough to ride out a glitch, short enough that a stuck
    /// channel does not hold the servo at a stale pulse); log at most once a second.
    pub const DEFAULT: Self = Self {
        disable_after: Millis(500),
        log_interval: Millis(1000),
    };
}

/// Everything the frame driver needs, in physical units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverConfig {
    /// Time between frames (calls to [`FrameDriver::write_frame`](super::FrameDriver::write_frame)).
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
    /// use idle_head_core::driver::DriverConfig;
    /// const _: () = DriverConfig::DEFAULT.assert_valid();
    /// ```
    ///
    /// A wrong one fails the build ("driver config: `servos[roll].min_pulse`
    /// must be below `max_pulse`"):
    ///
    /// ```compile_fail
    /// use idle_head_core::driver::DriverConfig;
    /// use idle_head_core::Microseconds;
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
    /// use idle_head_core::driver::{ConfigError, DriverConfig};
    /// use idle_head_core::servo::ServoError;
    /// use idle_head_core::{Axis, Microseconds};
    /// let mut cfg = DriverConfig::DEFAULT;
    /// cfg.servos[1].min_pulse = Microseconds(2500);
    /// let err = cfg.build().unwrap_err();
    /// assert!(matches!(
    ///     err,
    ///     ConfigError::Servo { axis: Axis::Roll, error: ServoError::PulseRangeEmpty { .. } }
    /// ));
    /// assert_eq!(err.to_string(), "roll servo: min_pulse 2500 µs must be below max_pulse 2000 µs");
    /// ```
    pub const fn build(&self) -> Result<DriverParams, ConfigError> {
        let frame_us = self.frame_period.0;
        if frame_us == 0 {
            return Err(ConfigError::ZeroFramePeriod);
        }
        if self.pwm.period.0 == 0 {
            return Err(ConfigError::ZeroPwmPeriod);
        }
        if self.faults.disable_after.0 == 0 {
            return Err(ConfigError::ZeroDisableAfter);
        }
        let mut i = 0;
        while i < 3 {
            let axis = Axis::ALL[i];
            let cal = &self.servos[i];
            if let Err(e) = check_servo(axis, cal, self.pwm, self.neutral_pose[i]) {
                return Err(e);
            }
            if let Err(e) = slew_params(axis, self.motion[i], self.frame_period, cal.limits) {
                return Err(e);
            }
            i += 1;
        }
        let mut params = DriverParams {
            config: *self,
            log_frames: 0,
            disable_frames: 0,
        };
        params.count_frames();
        Ok(params)
    }
}

// The built-in configuration must be valid: a mistake fails the build.
const _: () = DriverConfig::DEFAULT.assert_valid();

/// Checks servo `axis`' calibration against the PWM timing and its neutral
/// pose: what [`DriverConfig::build`] and
/// [`FrameDriver::set_servo`](super::FrameDriver::set_servo) accept.
pub(crate) const fn check_servo(
    axis: Axis,
    cal: &ServoCalibration,
    pwm: PwmTiming,
    pose: Angle,
) -> Result<(), ConfigError> {
    if let Err(error) = cal.validate() {
        return Err(ConfigError::Servo { axis, error });
    }
    if cal.max_pulse.0 > pwm.period.0 {
        return Err(ConfigError::PulseLongerThanPeriod {
            axis,
            max_pulse: cal.max_pulse,
            period: pwm.period,
        });
    }
    let (lo, hi) = (cal.limits.min.millidegrees(), cal.limits.max.millidegrees());
    if lo < -MAX_LIMIT_MDEG {
        return Err(ConfigError::LimitOutOfRange {
            axis,
            limit: cal.limits.min,
        });
    }
    if hi > MAX_LIMIT_MDEG {
        return Err(ConfigError::LimitOutOfRange {
            axis,
            limit: cal.limits.max,
        });
    }
    if !cal.limits.contains(pose) {
        return Err(ConfigError::NeutralPoseOutsideLimits {
            axis,
            pose,
            limits: cal.limits,
        });
    }
    Ok(())
}

/// The limiter parameters of `motion` at `frame_period` between `limits`
/// (validated by [`check_servo`]).
pub(crate) const fn slew_params(
    axis: Axis,
    motion: MotionLimits,
    frame_period: Microseconds,
    limits: AngleRange,
) -> Result<SlewParams, ConfigError> {
    match slew_rates(axis, motion, frame_period) {
        Ok(rates) => Ok(SlewParams::with_rates(
            rates,
            limits.min.millidegrees(),
            limits.max.millidegrees(),
        )),
        Err(e) => Err(e),
    }
}

/// The per-frame rates of `motion` at `frame_period`.
pub(crate) const fn slew_rates(
    axis: Axis,
    motion: MotionLimits,
    frame_period: Microseconds,
) -> Result<SlewRates, ConfigError> {
    const US_PER_S: u64 = 1_000_000;
    let frame_us = frame_period.0 as u64;
    // deg/s · 10^6 µ°/° · frame_us / 10^6 µs/s = µ° per frame.
    let step = motion.max_speed.0 as u64 * frame_us;
    // deg/s² · 10^6 µ°/° · (frame_us / 10^6)² = µ° per frame²; < 2^96.
    // In u64 when it fits (every servo rate): a u128 division costs the
    // frame task tens of thousands of cycles on a Cortex-M0+ at a change
    // of rate.
    let square = frame_us * frame_us;
    let accel = match (motion.max_accel.0 as u64).checked_mul(square) {
        Some(product) => (product / US_PER_S) as u128,
        None => motion.max_accel.0 as u128 * square as u128 / US_PER_S as u128,
    };
    if step == 0 {
        return Err(ConfigError::ZeroSpeedLimit { axis });
    }
    if accel == 0 {
        return Err(ConfigError::AccelBelowResolution {
            axis,
            max_accel: motion.max_accel,
            frame_period,
        });
    }
    let accel = if accel > u64::MAX as u128 {
        u64::MAX
    } else {
        accel as u64
    };
    Ok(SlewRates::new(step, accel))
}

/// Whole frames in `us` microseconds, rounded up, saturating at `u32::MAX`.
const fn frames_in(us: u64, frame_us: u32) -> u32 {
    let f = us.div_ceil(if frame_us == 0 { 1 } else { frame_us as u64 });
    if f > u32::MAX as u64 {
        u32::MAX
    } else {
        f as u32
    }
}

/// A validated [`DriverConfig`] in the integer form the frame path uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverParams {
    pub(crate) config: DriverConfig,
    pub(crate) log_frames: u32,
    pub(crate) disable_frames: u16,
}

impl DriverParams {
    /// The configuration these parameters were built from.
    #[must_use]
    pub const fn config(&self) -> &DriverConfig {
        &self.config
    }

    /// The fade's duration, µs (at most about 35 minutes).
    #[must_use]
    pub const fn fade_us(&self) -> u32 {
        let us = self.config.fade.0 as u64 * 1000;
        let most = super::envelope::MAX_FADE as u64;
        if us > most { most as u32 } else { us as u32 }
    }

    /// Frames of the fade-in and fade-out at the frame period (rounded up).
    #[must_use]
    pub const fn fade_frames(&self) -> u32 {
        frames_in(self.fade_us() as u64, self.config.frame_period.0)
    }

    /// Failed frames in a row after which a servo is switched off: the
    /// fault policy's time at the frame period, rounded up, at least 1.
    #[must_use]
    pub const fn disable_frames(&self) -> u16 {
        self.disable_frames
    }

    /// Works out the frame counts of the fault policy for the frame period.
    pub(crate) const fn count_frames(&mut self) {
        let frame_us = self.config.frame_period.0;
        let faults = self.config.faults;
        self.log_frames = frames_in(faults.log_interval.0 as u64 * 1000, frame_us);
        let disable = frames_in(faults.disable_after.0 as u64 * 1000, frame_us);
        self.disable_frames = if disable == 0 {
            1
        } else if disable > u16::MAX as u32 {
            u16::MAX
        } else {
            disable as u16
        };
    }

    /// Largest change of the commanded angle of `axis` from one frame to the
    /// next (the speed limit per frame, rounded up to whole millidegrees).
    #[must_use]
    pub const fn max_step(&self, axis: Axis) -> Angle {
        let speed = self.config.motion[axis.index()].max_speed.0 as u64;
        let m = (speed * self.config.frame_period.0 as u64).div_ceil(1000);
        Angle::from_millidegrees(if m > i32::MAX as u64 {
            i32::MAX
        } else {
            m as i32
        })
    }
}
