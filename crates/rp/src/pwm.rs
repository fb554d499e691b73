//! A servo output on its own RP2040 PWM slice, silent until its first duty.
//!
//! The pin is low from reset until the first [`SetDutyCycle::set_duty_cycle`]
//! (the neutral pulse), which starts the slice a tenth of a period
//! ([`WRAP_MARGIN_DIVISOR`]) before its wrap: the first pulse is whole. The
//! PWM period is exactly one frame, so each frame's duty is latched at the
//! next wrap and goes out as exactly one pulse, none cut, none twice. A new
//! period ([`SetPeriod::set_period`]) is taken the same way at the next
//! duty written.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Servo outputs on RP2040 PWM”).

use embassy_rp::Peri;
use embassy_rp::pwm::{ChannelAPin, Config, Pwm, PwmError, Slice};
use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use fixed::FixedU16;
use fixed::types::extra::U4;

use idle_head_core::Microseconds;
use idle_head_core::pwm_clock::SliceClock;
use idle_head_core::servo::SetPeriod;

use crate::SYS_HZ;

/// The wrap that latches a frame's duty comes a period over this after the
/// write (a tenth: 2 ms of a 20 ms frame, 0.3 ms at 333 Hz); see the module
/// docs.
pub use idle_head_core::pwm_clock::WRAP_MARGIN_DIVISOR;

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
        // First duty at this period: slice off, compare value, the counter
        // a tenth of a period before its wrap, then run (the slice's start
        // latches `TOP` and the compare value).
        self.config.compare_a = duty;
        self.config.enable = false;
        self.pwm.set_config(&self.config);
        let counts = u32::from(self.config.top) + 1;
        let margin = counts / WRAP_MARGIN_DIVISOR;
        self.pwm.set_counter((counts - margin) as u16);
        self.config.enable = true;
        self.pwm.set_config(&self.config);
        self.running = true;
        Ok(())
    }
}

impl SetPeriod for ServoPwm {
    const LATCH_DIVISOR: u32 = WRAP_MARGIN_DIVISOR;

    /// The clock of `period` from the system clock, exactly (see the
    /// module docs): it takes effect at the next duty written.
    fn set_period(&mut self, period: Microseconds) -> Result<(), PwmError> {
        let Ok(clock) = SliceClock::for_period(SYS_HZ, period) else {
            return Err(PwmError::InvalidDutyCycle);
        };
        let divider = FixedU16::<U4>::from_bits(clock.divider_16ths);
        if divider == self.config.divider && clock.top == self.config.top {
            return Ok(());
        }
        self.config.divider = divider;
        self.config.top = clock.top;
        self.running = false;
        Ok(())
    }
}
