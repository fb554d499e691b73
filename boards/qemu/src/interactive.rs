//! The frame hooks of an interactive run (`interactive` on the semihosting
//! command line, see `console.rs`): a clean head for a person at the
//! console or the panel. No script, no injected fault, no schedule: the
//! frames play at the board's 20 ms until the host hangs up. Every pulse
//! written is judged against the calibration in effect at that frame (the
//! console may change it), as the smoke run's checks do.

use core::sync::atomic::Ordering;

use idle_head_core::Axis;
use idle_head_core::driver::{FrameDriver, Outcome};
use idle_head_core::servo::ServoCalibration;
use idle_head_firmware::frame::{Flow, Frame, FrameHooks};

use crate::pwm::VirtualPwm;

/// Hooks of an interactive run.
pub struct Interactive {
    /// The calibrations the outputs judge by (the console may change them).
    known: [ServoCalibration; 3],
}

impl Interactive {
    /// Hooks for outputs judging by `servos`, the calibrations the run
    /// starts with.
    pub const fn new(servos: [ServoCalibration; 3]) -> Self {
        Self { known: servos }
    }
}

impl FrameHooks<VirtualPwm> for Interactive {
    fn after_frame(&mut self, frame: &Frame, driver: &mut FrameDriver<VirtualPwm>) -> Flow {
        let servos = driver.params().config().servos;
        // The outputs judge the next pulses by the range in effect (and
        // count what falls outside it: the run's violations).
        for ((known, cal), channel) in self
            .known
            .iter_mut()
            .zip(&servos)
            .zip(driver.channels_mut().iter_mut())
        {
            if known != cal {
                *known = *cal;
                channel.judge(cal);
            }
        }
        for ((axis, servo), cal) in Axis::ALL.iter().zip(&frame.report.servos).zip(&servos) {
            if servo.outcome == Outcome::Written
                && (servo.pulse < cal.min_pulse || servo.pulse > cal.max_pulse)
            {
                defmt::error!(
                    "check: frame {=u64}: {=str} pulse {=u32} us outside {=u32}..{=u32} us",
                    frame.tick.frame,
                    axis.name(),
                    servo.pulse.0,
                    cal.min_pulse.0,
                    cal.max_pulse.0
                );
            }
        }
        if crate::console::HUNG_UP.load(Ordering::Acquire) {
            Flow::Stop
        } else {
            Flow::Continue
        }
    }
}
