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
//!   pulse) writes the compare value, sets the counter a tenth of a period
//!   ([`WRAP_MARGIN_DIVISOR`]) before its wrap (above any servo's compare value, so the output
//!   stays low) and only then enables the slice. The first wrap comes that
//!   much later and starts the first pulse: the whole neutral pulse.
//! - Later writes change the compare value while the slice runs; the RP2040
//!   latches it at the next wrap, so a pulse is never cut or stretched.
//!
//! # One frame, one pulse
//!
//! The PWM period is exactly one frame (`idle_head_core::pwm_clock`) and
//! both come from the same crystal, so the frames' writes keep the phase the
//! first one set: each lands a tenth of a period ([`WRAP_MARGIN_DIVISOR`];
//! 2 ms at 50 Hz, 0.3 ms at 333 Hz) before the wrap that latches it,
//! whatever the frame's wake-up latency or cost, as long as it is below
//! that (it is tens of microseconds: the frame task runs above everything
//! but the timer's alarm). Frame `k` is latched at wrap `k + 1` and goes out
//! as the `k`-th pulse: no frame is ever overwritten before it went out,
//! none goes out twice.
//!
//! The margin is what a frame's pulse waits after its write: the smaller,
//! the sooner a command shows on the servo. Half a period (10 ms) would
//! forgive any lateness below 10 ms and put 10 ms into every command's
//! latency; 2 ms forgives a hundred times the lateness measured and costs
//! 2 ms. A frame written later still goes out, a period late, as the
//! previous frame's pulse repeated once.
//!
//! # A new period (`servo rate`)
//!
//! [`SetPeriod::set_period`] only keeps the new divider and `TOP`; the next
//! duty written starts the slice over as the first one does: slice off, the
//! new divider, `TOP` and compare value, the counter a tenth of the new
//! period before its wrap, slice on (which latches `TOP` and the compare
//! value). That write is the last frame's at the old spacing, a tenth of
//! the old period before the old wrap: the old period's pulse has ended
//! (every pulse is at most 2.5 ms, below nine tenths of any period of the
//! range), the output is low, and it stays low until the new first wrap a
//! tenth of the new period later, where that frame's pulse starts. The
//! frames after it come one new period apart: the phase rule holds on.

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
