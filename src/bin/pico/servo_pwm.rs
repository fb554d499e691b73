//! A servo output on its own RP2040 PWM slice, silent until its first duty.
//!
//! # No pulse before the first valid frame
//!
//! - From reset until [`ServoPwm::new`] the pin is an unconnected GPIO
//!   (function NULL) with the RP2040's reset pad setting, pull-down enabled:
//!   the servo input sees a low level.
//! - [`ServoPwm::new`] gives the pin to the slice with the slice *disabled*,
//!   its counter at 0 and its compare value at 0, so the output is driven low
//!   (the output is high only while the counter is below the compare value).
//! - The first [`SetDutyCycle::set_duty_cycle`] (the frame driver's neutral
//!   pulse) writes the compare value and only then enables the slice, with the
//!   counter still at 0: the first period starts at the beginning of a whole
//!   pulse. (If the compare write only lands at the first wrap, as the
//!   double-buffered compare register does while running, the first period
//!   is simply low and the next one a whole pulse.)
//! - Later writes change the compare value while the slice runs; the RP2040
//!   latches it at the next wrap, so a pulse is never cut or stretched.

use embassy_rp::Peri;
use embassy_rp::pwm::{ChannelAPin, Config, Pwm, PwmError, Slice};
use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use fixed::FixedU16;
use fixed::types::extra::U4;
use idle_head::firmware::rp2040_pwm::SliceClock;

/// One servo output: channel A of a PWM slice of its own.
pub struct ServoPwm {
    pwm: Pwm<'static>,
    config: Config,
    running: bool,
}

impl ServoPwm {
    /// Takes `slice` and its channel A `pin`, clocked by `clock`; the output
    /// stays low until the first duty is written.
    pub fn new<S: Slice>(
        slice: Peri<'static, S>,
        pin: Peri<'static, impl ChannelAPin<S>>,
        clock: &SliceClock,
    ) -> Self {
        let mut config = Config::default();
        config.divider = FixedU16::<U4>::from_bits(clock.divider_16ths);
        config.top = clock.top;
        config.compare_a = 0;
        config.compare_b = 0;
        config.enable = false;
        Self {
            pwm: Pwm::new_output_a(slice, pin, config.clone()),
            config,
            running: false,
        }
    }
}

impl ErrorType for ServoPwm {
    type Error = PwmError;
}

impl SetDutyCycle for ServoPwm {
    fn max_duty_cycle(&self) -> u16 {
        self.config.top
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        if self.running {
            return self.pwm.set_duty_cycle(duty);
        }
        if duty > self.config.top {
            return Err(PwmError::InvalidDutyCycle);
        }
        // First duty: compare value first, then start the counter from 0.
        self.config.compare_a = duty;
        self.config.enable = true;
        self.pwm.set_config(&self.config);
        self.running = true;
        Ok(())
    }
}
