//! Changes to a running driver: new motion limits for an axis, and a new
//! calibration for a servo, each from the next frame on, without a jump.

use embedded_hal::pwm::SetDutyCycle;

use crate::axis::Axis;
use crate::servo::{ServoCalibration, ServoMap};

use super::super::config::{check_servo, slew_params};
use super::super::limiter::{Slew, SlewParams, SlewRates};
use super::super::{ConfigError, MotionLimits};
use super::{FrameDriver, ServoState};

impl<P: SetDutyCycle> FrameDriver<P> {
    /// New speed and acceleration limits for `axis` from the next frame on,
    /// validated as [`DriverConfig::build`](super::DriverConfig::build) does.
    ///
    /// An axis moving faster than a lowered speed limit slows down at the
    /// acceleration limit; braking onto the target stays exact. (An axis
    /// braking when its acceleration limit is lowered may no longer stop in
    /// time: it overshoots within the new limits and comes back.) The angle
    /// limits are never passed: an axis that can no longer stop before one
    /// at the lowered acceleration brakes harder than it allows. To switch
    /// without that, use [`set_motion_limits_when_safe`](Self::set_motion_limits_when_safe).
    ///
    /// # Errors
    /// [`ConfigError::ZeroSpeedLimit`] or [`ConfigError::AccelBelowResolution`];
    /// the limits in use are then unchanged.
    pub fn set_motion_limits(
        &mut self,
        axis: Axis,
        limits: MotionLimits,
    ) -> Result<(), ConfigError> {
        if let Some((params, motion, servo)) = self.motion_slots(axis, limits)? {
            servo.limits = params;
            *motion = limits;
        }
        Ok(())
    }

    /// As [`set_motion_limits`](Self::set_motion_limits), but only if
    /// `axis` can take `limits` from the next frame on with no step beyond
    /// them: it moves no faster than their speed limit and, at their
    /// acceleration limit, can still stop before the angle limit it moves
    /// towards. `Ok(false)` (the limits in use unchanged) if it cannot yet.
    ///
    /// # Errors
    /// As [`set_motion_limits`](Self::set_motion_limits).
    pub fn set_motion_limits_when_safe(
        &mut self,
        axis: Axis,
        limits: MotionLimits,
    ) -> Result<bool, ConfigError> {
        let Some((params, motion, servo)) = self.motion_slots(axis, limits)? else {
            return Ok(false);
        };
        Ok(Self::switch_when_safe(servo, motion, params, limits))
    }

    /// `axis`' per-frame limits for `limits`, with the configuration's and
    /// the servo's slots they go in (`None` for no such servo).
    fn motion_slots(
        &mut self,
        axis: Axis,
        limits: MotionLimits,
    ) -> Result<Option<(SlewParams, &mut MotionLimits, &mut ServoState)>, ConfigError> {
        let frame_period = self.params.config.frame_period;
        let Some((cal, motion, servo)) = self.slots(axis) else {
            return Ok(None);
        };
        let params = slew_params(axis, limits, frame_period, cal.limits)?;
        Ok(Some((params, motion, servo)))
    }

    /// `axis`' calibration, with the configuration's motion limits and the
    /// servo's state (`None` for no such servo).
    fn slots(
        &mut self,
        axis: Axis,
    ) -> Option<(&ServoCalibration, &mut MotionLimits, &mut ServoState)> {
        let i = axis.index();
        let config = &mut self.params.config;
        match (
            config.servos.get(i),
            config.motion.get_mut(i),
            self.servos.get_mut(i),
        ) {
            (Some(cal), Some(motion), Some(servo)) => Some((cal, motion, servo)),
            _ => None,
        }
    }

    /// Switches `servo` to `params` (for `limits`) if it can take them with
    /// no step beyond them; whether it did.
    fn switch_when_safe(
        servo: &mut ServoState,
        motion: &mut MotionLimits,
        params: SlewParams,
        limits: MotionLimits,
    ) -> bool {
        if !servo.slew.can_take(&params) {
            return false;
        }
        servo.limits = params;
        *motion = limits;
        true
    }

    /// As [`set_motion_limits_when_safe`](Self::set_motion_limits_when_safe),
    /// with `limits`' per-frame rates computed before for a frame period of
    /// `frame_us` (a switch between two sets of limits used again and again
    /// is then a copy and a few additions: no division). Without rates, or
    /// for another frame period than the driver's, they are computed here.
    ///
    /// # Errors
    /// As [`set_motion_limits`](Self::set_motion_limits).
    pub(crate) fn set_rates_when_safe(
        &mut self,
        axis: Axis,
        limits: MotionLimits,
        rates: Option<SlewRates>,
        frame_us: u32,
    ) -> Result<bool, ConfigError> {
        let Some(rates) = rates.filter(|_| self.params.config.frame_period.0 == frame_us) else {
            return self.set_motion_limits_when_safe(axis, limits);
        };
        let Some((cal, motion, servo)) = self.slots(axis) else {
            return Ok(false);
        };
        let params = SlewParams::with_rates(
            rates,
            cal.limits.min.millidegrees(),
            cal.limits.max.millidegrees(),
        );
        Ok(Self::switch_when_safe(servo, motion, params, limits))
    }

    /// A new calibration for `axis`' servo from the next frame on, validated
    /// as [`DriverConfig::build`](super::DriverConfig::build) does.
    ///
    /// The servo does not jump: its limiter is re-anchored at the angle where
    /// the new calibration puts the last pulse it received, moving at the same
    /// pulse rate, so the pulses go on from the last one written; the head
    /// then moves to where the new calibration puts its target, within the
    /// speed and acceleration limits. (Only the new pulse and angle limits are
    /// hard: a servo standing outside the new angle limits moves back in, and
    /// a pulse outside the new pulse range is clamped to it.)
    ///
    /// # Errors
    /// Any [`ConfigError`] that `build` gives for this servo; the calibration
    /// in use is then unchanged.
    pub fn set_servo(&mut self, axis: Axis, cal: ServoCalibration) -> Result<(), ConfigError> {
        let i = axis.index();
        let config = &mut self.params.config;
        let (Some(&pose), Some(motion), Some(servo), Some(old)) = (
            config.neutral_pose.get(i),
            config.motion.get(i),
            self.servos.get_mut(i),
            config.servos.get_mut(i),
        ) else {
            return Ok(());
        };
        check_servo(axis, &cal, config.pwm, pose)?;
        let limits = slew_params(axis, *motion, config.frame_period, cal.limits)?;
        let map = ServoMap::new(&cal, config.pwm, servo.map.max_duty());
        if self.started {
            // The limiter stands where the last pulse received put the servo
            // (a failed write leaves it there).
            let duty = servo.map.duty(old, servo.slew.angle());
            let anchor = map.angle_of_duty(&cal, duty);
            let vel = same_pulse_rate(servo.slew.velocity(), old, &cal);
            servo.slew = Slew::anchored(anchor, vel);
        }
        servo.map = map;
        servo.limits = limits;
        *old = cal;
        Ok(())
    }
}

/// The step `vel` (µ°/frame in `old`'s angles) as the same pulse rate in
/// `new`'s angles, rounded to the nearest µ°.
fn same_pulse_rate(vel: i32, old: &ServoCalibration, new: &ServoCalibration) -> i32 {
    let signed = |cal: &ServoCalibration| {
        let s = i64::from(cal.per_degree.0);
        match cal.direction {
            crate::servo::Direction::Normal => s,
            crate::servo::Direction::Reversed => -s,
        }
    };
    let (from, to) = (signed(old), signed(new));
    if to == 0 {
        return 0;
    }
    // |vel·from| < 2³¹·2³²: fits i64.
    let num = i64::from(vel) * from;
    let (q, r) = (num / to, num % to);
    let q = if 2 * r.unsigned_abs() >= to.unsigned_abs() {
        q + (num.signum() * to.signum())
    } else {
        q
    };
    q.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
}
