//! The embassy frame task shared by the board images (feature `firmware`).
//!
//! Embassy tasks cannot be generic, so each board image has a one-line
//! `#[embassy_executor::task]` that calls [`run`] with its own PWM type and
//! its own [`FrameHooks`] (the QEMU image checks invariants and logs frames,
//! the Pico feeds its watchdog).
//!
//! # Timing
//!
//! Frames are due at `start + k · period` exactly ([`FrameClock`]), and the
//! task sleeps with [`Timer::at`] until the next deadline. The deadlines
//! never drift. A frame that wakes up a whole period or more late is counted
//! as missed and skipped, together with any other frame whose deadline has
//! passed: the next deadline lies in the future, so a stall is never followed
//! by a burst of catch-up writes (which `embassy_time::Ticker` would do).
//!
//! # No panics
//!
//! The work of one frame, [`FrameLoop::next`] then [`FrameLoop::write`], is
//! the code linked by the `frame-path-proof` image against a panic handler
//! that does not exist (see `qemu/src/panic_proof.rs`): the image only links if
//! no panic path survives optimisation.

pub mod rp2040_pwm;

use embassy_time::{Duration, Instant, Timer};
use embedded_hal::pwm::SetDutyCycle;

use crate::Angle;
use crate::driver::{FrameClock, FrameDriver, FrameReport, FrameTick, ZeroPeriod};
use crate::playback::{LoopSource, Playback};

/// Loop duration of the idle motion on the boards: 30 s, the longer end of
/// the 15 to 30 s waits the paper recorded. With the 900 samples of a loop
/// (`DEFAULT_N`) that is 30 samples per second; at 50 frames per second
/// there are 30 s / 20 ms = 1500 frames per loop.
pub const LOOP_DURATION: crate::Millis = crate::Millis(30_000);

/// One frame of the loop: what [`FrameLoop::write`] played.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame {
    /// Frame index and frames skipped just before it.
    pub tick: FrameTick,
    /// When the frame was due, in embassy ticks.
    pub deadline: u64,
    /// When the task woke up to play it, in embassy ticks.
    pub woke: u64,
    /// Trajectory offsets `[pitch, roll, yaw]` before fade and limits.
    pub offsets: [Angle; 3],
    /// What the driver wrote.
    pub report: FrameReport,
}

/// What the frame task should do after a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Flow {
    /// Play the next frame.
    Continue,
    /// Return from [`run`].
    Stop,
}

/// Board hooks around every frame of [`run`].
pub trait FrameHooks<P: SetDutyCycle> {
    /// Called when frame `tick` is due, before it is written.
    fn before_frame(&mut self, tick: &FrameTick, driver: &mut FrameDriver<P>) {
        let _ = (tick, driver);
    }

    /// Called after each frame has been written.
    fn after_frame(&mut self, frame: &Frame, driver: &mut FrameDriver<P>) -> Flow;
}

/// Totals returned by [`run`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RunStats {
    /// Frames written (the start frame included).
    pub frames: u64,
    /// Frames skipped because the task woke up a period or more late.
    pub missed: u64,
    /// Largest wake-up delay after a deadline, in embassy ticks.
    pub max_lateness: u64,
}

/// The playback state of the frame task: which frame is due when, and where
/// it lies in the loops.
#[derive(Debug)]
pub struct FrameLoop<'a, L: LoopSource + ?Sized> {
    playback: Playback,
    loops: [&'a L; 3],
    clock: FrameClock,
}

impl<'a, L: LoopSource + ?Sized> FrameLoop<'a, L> {
    /// Frames of `playback` over `loops` (`[pitch, roll, yaw]`), frame 0 due at
    /// `start`; times are in ticks of `tick_hz`.
    ///
    /// # Errors
    /// [`ZeroPeriod`] if the frame period is shorter than one tick.
    pub const fn new(
        playback: Playback,
        loops: [&'a L; 3],
        tick_hz: u64,
        start: u64,
    ) -> Result<Self, ZeroPeriod> {
        // µs · ticks/s / 10^6 µs/s; frame period < 2^32 µs, tick_hz < 2^32
        // for any real timer: no overflow.
        let period = playback.frame_period().get() as u64 * tick_hz / 1_000_000;
        match FrameClock::new(period, start) {
            Ok(clock) => Ok(Self {
                playback,
                loops,
                clock,
            }),
            Err(e) => Err(e),
        }
    }

    /// When the next frame is due.
    #[must_use]
    pub const fn deadline(&self) -> u64 {
        self.clock.deadline()
    }

    /// Frames skipped so far.
    #[must_use]
    pub const fn missed(&self) -> u64 {
        self.clock.skipped_total()
    }

    /// The playback parameters.
    #[must_use]
    pub const fn playback(&self) -> &Playback {
        &self.playback
    }

    /// The frame to play at `now` (skipping the ones whose time has passed).
    pub fn next(&mut self, now: u64) -> FrameTick {
        self.clock.tick(now)
    }

    /// Writes frame `tick`: its loop offsets through `driver`. The first
    /// call starts the driver (neutral pulses) instead.
    pub fn write<P: SetDutyCycle>(
        &self,
        driver: &mut FrameDriver<P>,
        tick: FrameTick,
    ) -> ([Angle; 3], FrameReport) {
        let offsets = self.playback.offsets(tick.frame, self.loops);
        (offsets, driver.write_frame(offsets))
    }
}

/// Plays `frames` through `driver` until `hooks` says stop.
///
/// The first frame is due at once and writes the neutral pose
/// ([`FrameDriver::start`]); the motion then fades in. Late frames and PWM
/// faults are logged (faults at most as often as the driver's fault policy
/// suggests).
pub async fn run<P, L, H>(
    driver: &mut FrameDriver<P>,
    frames: &mut FrameLoop<'_, L>,
    hooks: &mut H,
) -> RunStats
where
    P: SetDutyCycle,
    L: LoopSource + ?Sized,
    H: FrameHooks<P>,
{
    let mut max_lateness = 0;
    loop {
        let deadline = frames.deadline();
        Timer::at(Instant::from_ticks(deadline)).await;
        let woke = Instant::now().as_ticks();
        let tick = frames.next(woke);
        let lateness = woke.saturating_sub(deadline);
        max_lateness = max_lateness.max(lateness);
        if tick.skipped > 0 {
            defmt::warn!(
                "frame {=u64}: woke {=u64} us late, skipped {=u64} frame(s)",
                tick.frame,
                Duration::from_ticks(lateness).as_micros(),
                tick.skipped
            );
        }
        hooks.before_frame(&tick, driver);
        let (offsets, report) = frames.write(driver, tick);
        if report.should_log {
            log_faults(&report);
        }
        let frame = Frame {
            tick,
            deadline,
            woke,
            offsets,
            report,
        };
        if hooks.after_frame(&frame, driver) == Flow::Stop {
            return RunStats {
                frames: driver.stats().frames,
                missed: frames.missed(),
                max_lateness,
            };
        }
    }
}

fn log_faults(report: &FrameReport) {
    use crate::driver::Outcome;
    for (axis, servo) in crate::Axis::ALL.iter().zip(report.servos.iter()) {
        match servo.outcome {
            Outcome::Failed(kind) => defmt::warn!(
                "frame {=u64}: {=str} PWM write failed ({}); {=u32} fault(s) since the last report",
                report.frame,
                axis.name(),
                kind,
                report.unlogged_faults
            ),
            Outcome::Disabled(kind) => defmt::error!(
                "frame {=u64}: {=str} PWM keeps failing ({}): servo switched off",
                report.frame,
                axis.name(),
                kind
            ),
            Outcome::Written | Outcome::Off => {}
        }
    }
}
