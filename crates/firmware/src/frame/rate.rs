//! `servo rate` in the frame task, in two steps (the driver's
//! `frame/rate.rs`): before a frame the outputs take the new period from
//! that frame's write on; after it the frames come the new period apart.

use embedded_hal::pwm::SetDutyCycle;
use idle_head_core::Microseconds;
use idle_head_core::behaviour::IdleSource;
use idle_head_core::console::ConsoleLink;
use idle_head_core::driver::{FrameDriver, FrameTick};
use idle_head_core::servo::SetPeriod;

use super::FrameLoop;

use crate::log;

/// A change of rate between its two steps, and the clock's scale.
#[derive(Clone, Debug)]
pub(super) struct Retime {
    /// The board's ticks for `us` of the frames' time (1 µs a µs on a
    /// board, faster in the QEMU smoke run).
    ticks: u64,
    us: u32,
    /// A period the outputs took before this frame: the frames follow it.
    pub(super) pending: Option<Microseconds>,
    /// A period the frames refused after the outputs took it (never: the
    /// configuration was checked at both), logged before the next frame:
    /// the frame path does not log.
    refused: Option<Microseconds>,
}

impl Retime {
    /// No change under way; `ticks` board ticks for `us` of frame time.
    pub(super) const fn new(ticks: u64, us: u32) -> Self {
        Self {
            ticks,
            us,
            pending: None,
            refused: None,
        }
    }
}

impl<I: IdleSource> FrameLoop<'_, I> {
    /// Before frame `tick`: the servos' rate the console set, if linked
    /// and it did: the outputs run at its period from this frame's write
    /// on, and the frames come that far apart after it (in
    /// [`write`](Self::write)).
    pub fn take_rate<P: SetPeriod>(&mut self, driver: &mut FrameDriver<P>, tick: FrameTick) {
        if let Some(period) = self.retime.refused.take() {
            log::error!("frames at {=u32} us refused by the driver", period.0);
        }
        let Some(rate) = self.link.and_then(ConsoleLink::take_rate) else {
            return;
        };
        let period = rate.period();
        match driver.set_pwm_period(period) {
            Ok(()) => {
                self.retime.pending = Some(period);
                log::info!(
                    "frame {=u64}: servo rate {=u16} Hz: pulses every {=u32} us from this frame on",
                    tick.frame,
                    rate.hz(),
                    period.0
                );
            }
            Err(e) => log::warn!("frame {=u64}: servo rate refused: {}", tick.frame, e),
        }
    }

    /// After the frame the new period's outputs were set before: the
    /// frames `period` apart from the next one on (the divisions of a
    /// change of rate happen here, once).
    #[inline(never)]
    pub(super) fn retime_frames<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        period: Microseconds,
    ) {
        if self.head.set_frame_period(driver, period).is_err() {
            self.retime.refused = Some(period);
            return;
        }
        let ticks = u64::from(period.0)
            .saturating_mul(self.retime.ticks)
            .checked_div(u64::from(self.retime.us))
            .unwrap_or(1);
        self.clock.set_period(ticks.max(1), period);
    }
}
