//! A change of the servos' rate on a running driver (`servo rate`), in two
//! steps around one frame, so that the motion goes on without a jump:
//!
//! 1. [`FrameDriver::set_pwm_period`], before the last frame at the old
//!    spacing is written: the outputs take the new period from that write
//!    on (an RP slice restarts its period there, a tenth of the new period
//!    before the wrap that latches it), and the duties are counted in the
//!    new period's counts.
//! 2. [`FrameDriver::set_frame_period`], after that frame: the frames come
//!    the new period apart from the next one on. The per-frame limits are
//!    worked out for it, the limiter's speed (µ° per frame) is scaled to
//!    it, the fade's level moves on by the new period instead of the old,
//!    and the fault policy is counted in the new frames.
//!
//! The frame between the two is the last one the old spacing times, and
//! its pulse the first at the new period. Every division happens here,
//! between frames: the frame path divides nothing.

use embedded_hal::pwm::SetDutyCycle;

use crate::axis::Axis;
use crate::servo::{ServoMap, SetPeriod};
use crate::units::Microseconds;

use super::super::config::slew_params;
use super::super::error::{ConfigError, RateError};
use super::FrameDriver;

impl<P: SetDutyCycle> FrameDriver<P> {
    /// Runs the servo outputs at `period` from the next frame written on
    /// (step 1 of the [module docs](self)): the configuration is checked
    /// at that period as [`DriverConfig::build`](super::DriverConfig::build)
    /// checks it, each output set ([`SetPeriod::set_period`]), and each
    /// servo's duties counted in its output's new counts. Also what a
    /// board does before the first frame, to start its outputs at the
    /// settings' period.
    ///
    /// # Errors
    /// [`RateError::Config`] if the configuration does not hold at that
    /// period, [`RateError::Output`] if an output cannot run at it (the
    /// others are set back); nothing changes then.
    pub fn set_pwm_period(&mut self, period: Microseconds) -> Result<(), RateError>
    where
        P: SetPeriod,
    {
        let mut next = self.params.config;
        next.frame_period = period;
        next.pwm.period = period;
        next.build().map_err(RateError::Config)?;
        let old = self.params.config.pwm.period;
        for (i, axis) in Axis::ALL.iter().enumerate() {
            let Some(channel) = self.channels.get_mut(i) else {
                continue;
            };
            if channel.set_period(period).is_err() {
                for earlier in self.channels.iter_mut().take(i) {
                    let _ = earlier.set_period(old);
                }
                return Err(RateError::Output {
                    axis: *axis,
                    period,
                });
            }
        }
        self.params.config.pwm = next.pwm;
        let config = &self.params.config;
        for ((servo, cal), channel) in self
            .servos
            .iter_mut()
            .zip(&config.servos)
            .zip(&self.channels)
        {
            servo.map = ServoMap::new(cal, config.pwm, channel.max_duty_cycle());
        }
        Ok(())
    }

    /// Plays the frames `period` apart from the next frame on (step 2 of
    /// the [module docs](self)), after the frame that
    /// [`set_pwm_period`](Self::set_pwm_period) came before.
    ///
    /// # Errors
    /// [`RateError::Config`] if the configuration does not hold at that
    /// period (it held at `set_pwm_period`); nothing changes then.
    pub fn set_frame_period(&mut self, period: Microseconds) -> Result<(), RateError> {
        let old = self.params.config.frame_period;
        if period == old {
            return Ok(());
        }
        // Of `DriverConfig::build`'s checks, only these two read the frame
        // period (the servos were checked at the new PWM period): the rest
        // held at `set_pwm_period` and at every frame since.
        if period.0 == 0 {
            return Err(RateError::Config(ConfigError::ZeroFramePeriod));
        }
        let config = &self.params.config;
        let mut limits = [None; 3];
        for (i, (slot, axis)) in limits.iter_mut().zip(Axis::ALL).enumerate() {
            if let (Some(motion), Some(cal)) = (config.motion.get(i), config.servos.get(i)) {
                *slot = Some(
                    slew_params(axis, *motion, period, cal.limits).map_err(RateError::Config)?,
                );
            }
        }
        for (servo, limits) in self.servos.iter_mut().zip(limits) {
            if let Some(limits) = limits {
                servo.limits = limits;
            }
            servo.slew.rescale(period.0, old.0);
        }
        self.params.config.frame_period = period;
        self.params.count_frames();
        self.envelope.set_frame_period(period.0);
        Ok(())
    }
}
