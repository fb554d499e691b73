//! The frame hooks of a board running on its own: a watchdog fed after every
//! frame, and a log line at the first frame (the status report once a loop
//! is [`crate::report`]'s, below every other task).
//!
//! The hardware watchdog is started just after the first frame (the neutral
//! pulses) and fed after every frame with [`WATCHDOG_TIMEOUT`] = 100 ms (5
//! frames), or longer while `save` or `load` uses the flash
//! ([`FlashBusy`]). If frames stop, the board resets; the
//! next boot logs that the last reset came from the watchdog and starts
//! softly again: outputs low, neutral pulses first, motion faded in.
//!
//! # Watchdog drill
//!
//! With the `watchdog-drill` feature (a test image, never shipped) frames
//! stop after [`DRILL_FRAMES`] frames of every boot, so that the watchdog
//! resets the board; `cargo xtask test` runs it in the RP2040 emulator and
//! checks the next boot.

use embassy_time::Duration;
use embedded_hal::pwm::SetDutyCycle;
use idle_head_core::driver::FrameDriver;
#[cfg(feature = "calibrate")]
use idle_head_core::playback::Playback;

use crate::frame::{Flow, Frame, FrameHooks};
use crate::log;
use crate::storage::FlashBusy;

/// Watchdog timeout: 100 ms = 5 frames of 20 ms. Long enough for a frame
/// that runs late, short enough that a stuck board stops driving its servos
/// quickly (a reset releases the pins: no pulses until the next soft start).
pub const WATCHDOG_TIMEOUT: Duration = Duration::from_millis(100);

/// Frames of each boot after which the drill image stops its frames: 3 s,
/// the 2 s fade-in and a second of motion.
pub const DRILL_FRAMES: u64 = 150;

/// A board's hardware watchdog.
pub trait Watchdog {
    /// Starts it: the board resets unless fed within `timeout`.
    fn start(&mut self, timeout: Duration);
    /// Feeds it, for another `timeout`.
    fn feed(&mut self, timeout: Duration);
}

/// Feeds the watchdog after every frame.
pub struct BoardHooks<W> {
    watchdog: W,
    /// Whether the settings store holds the flash.
    flash: &'static FlashBusy,
    started: bool,
    #[cfg(feature = "calibrate")]
    playback: Playback,
}

impl<W: Watchdog> BoardHooks<W> {
    /// Hooks feeding `watchdog`, longer while `flash` is busy.
    pub fn new(watchdog: W, flash: &'static FlashBusy) -> Self {
        Self {
            watchdog,
            flash,
            started: false,
            #[cfg(feature = "calibrate")]
            playback: crate::tasks::playback(),
        }
    }
}

impl<P: SetDutyCycle, W: Watchdog> FrameHooks<P> for BoardHooks<W> {
    fn after_frame(&mut self, frame: &Frame, driver: &mut FrameDriver<P>) -> Flow {
        let _ = driver;
        if self.started {
            self.watchdog.feed(self.flash.timeout(WATCHDOG_TIMEOUT));
        } else {
            // The first frame (neutral pulses) is out: from now on frames
            // must keep coming.
            self.watchdog.start(WATCHDOG_TIMEOUT);
            self.started = true;
            let [p, r, y] = frame.report.servos;
            // (Not the peak stack: its scan of the painted stack takes
            // milliseconds, more than a frame at 333 Hz has before the
            // next; the loop lines have it.)
            log::info!(
                "first frame: neutral pulses {=u32} {=u32} {=u32} us; watchdog armed ({=u64} ms)",
                p.pulse.0,
                r.pulse.0,
                y.pulse.0,
                WATCHDOG_TIMEOUT.as_millis()
            );
        }
        #[cfg(feature = "calibrate")]
        crate::calibrate::log_frame(frame, &self.playback);
        #[cfg(feature = "watchdog-drill")]
        if frame.tick.frame == DRILL_FRAMES {
            log::warn!(
                "watchdog drill: frames stop after frame {=u64}; the watchdog must reset the board",
                frame.tick.frame
            );
            return Flow::Stop;
        }
        Flow::Continue
    }
}
