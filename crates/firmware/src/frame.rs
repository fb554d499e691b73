//! The frame task's loop, shared by every board: [`run`] with a board's PWM
//! type and [`FrameHooks`] (embassy tasks cannot be generic).
//!
//! Frames are due at `start + k · period` exactly ([`FrameClock`]); a frame
//! that wakes a period or more late is skipped, never followed by a burst
//! of catch-up writes. Each frame is played by the core's frame engine
//! ([`Head`]) at its own time ([`FrameTick::at`]), with at most two queued
//! commands ([`CommandQueue`]) and the show layer's inputs ([`ShowLink`])
//! taken before it. The work of one frame ([`FrameLoop::next`],
//! [`FrameLoop::drain`], [`FrameLoop::write`]) has no panic path: the
//! `frame-path-proof` image (`boards/qemu/src/panic_proof.rs`) proves it.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The frame task”).

use core::sync::atomic::Ordering;

use embassy_time::{Duration, Instant, Timer};
use embedded_hal::pwm::SetDutyCycle;
use idle_head_core::servo::SetPeriod;
use portable_atomic::AtomicU32;

use idle_head_core::behaviour::{
    Applied, BehaviourError, BehaviourParams, CommandQueue, Head, HeadFrame, IdleSource,
    ShowEvents, ShowLink, TrackEvent,
};
use idle_head_core::command::Action;
use idle_head_core::console::{ConsoleLink, HeadMode, HeadStatus};
use idle_head_core::dmx::Signal;
use idle_head_core::driver::{FrameClock, FrameDriver, FrameReport, FrameTick, ZeroPeriod};
use idle_head_core::{Angle, Microseconds, Timestamp};

use crate::config::DEFAULT_BEHAVIOUR;
use crate::log;

mod rate;

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
    /// The mixer's offsets `[pitch, roll, yaw]` (idle, gaze and gestures)
    /// before fade and limits.
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

/// The frame task's state: which frame is due when, and the frame engine
/// that plays it over the idle source `I`.
#[derive(Clone, Debug)]
pub struct FrameLoop<'a, I> {
    head: Head<I>,
    clock: FrameClock,
    commands: Option<&'a CommandQueue>,
    link: Option<&'a ConsoleLink>,
    show: Option<&'a ShowLink>,
    /// A change of servo rate between its two steps.
    retime: rate::Retime,
    /// The last frame's time.
    at: Timestamp,
}

impl<'a, I: IdleSource> FrameLoop<'a, I> {
    /// Frames of `idle`, one every `frame_period`, frame 0 due at `start`;
    /// times are in ticks of `tick_hz`. The built-in behaviour (for the
    /// built-in driver configuration), no command queue.
    ///
    /// # Errors
    /// [`ZeroPeriod`] if the frame period is shorter than one tick.
    pub fn new(
        idle: I,
        frame_period: Microseconds,
        tick_hz: u64,
        start: u64,
    ) -> Result<Self, ZeroPeriod> {
        Self::with_behaviour(idle, frame_period, DEFAULT_BEHAVIOUR, tick_hz, start)
    }

    /// As [`new`](Self::new), with the behaviour `params` (built for the
    /// driver this loop will drive).
    ///
    /// # Errors
    /// [`ZeroPeriod`] if the frame period is shorter than one tick.
    pub fn with_behaviour(
        idle: I,
        frame_period: Microseconds,
        params: BehaviourParams,
        tick_hz: u64,
        start: u64,
    ) -> Result<Self, ZeroPeriod> {
        // µs · ticks/s / 10^6 µs/s; frame period < 2^32 µs, tick_hz < 2^32
        // for any real timer: no overflow.
        let period = u64::from(frame_period.get()) * tick_hz / 1_000_000;
        let clock = FrameClock::new(period, start, Microseconds(params.frame_us()))?;
        Ok(Self {
            head: Head::new(idle, params),
            clock,
            commands: None,
            link: None,
            show: None,
            retime: rate::Retime::new(period, params.frame_us()),
            at: Timestamp(0),
        })
    }

    /// Outputs that latch a duty a `1/divisor` of a period after the
    /// frame's deadline ([`SetPeriod::LATCH_DIVISOR`]): a frame that wakes
    /// later misses its pulse, and the clock skips to the next one.
    #[must_use]
    pub const fn with_latch_divisor(mut self, divisor: u32) -> Self {
        self.clock = self.clock.with_latch_divisor(divisor as u64);
        self
    }

    /// Takes commands from `queue` (at most two a frame).
    #[must_use]
    pub const fn with_commands(mut self, queue: &'a CommandQueue) -> Self {
        self.commands = Some(queue);
        self
    }

    /// Shares status and servo calibrations with the console through
    /// `link`: calibrations are applied before a frame
    /// ([`drain`](Self::drain)), the status published after it
    /// ([`publish`](Self::publish)).
    #[must_use]
    pub const fn with_link(mut self, link: &'a ConsoleLink) -> Self {
        self.link = Some(link);
        self
    }

    /// Takes the show layer's inputs from `show` before each frame: the
    /// DMX receiver's latest cue and Bottango's curves (see
    /// [`Head::show`]); publishes the DMX signal as judged there.
    #[must_use]
    pub const fn with_show(mut self, show: &'a ShowLink) -> Self {
        self.show = Some(show);
        self
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

    /// The frame engine.
    #[must_use]
    pub const fn head(&self) -> &Head<I> {
        &self.head
    }

    /// The idle source.
    pub fn idle_mut(&mut self) -> &mut I {
        self.head.idle_mut()
    }

    /// The frame to play at `now` (skipping the ones whose time has passed).
    pub fn next(&mut self, now: u64) -> FrameTick {
        self.clock.tick(now)
    }

    /// Applies `action` from the next frame on (see [`Head::apply`]).
    ///
    /// # Errors
    /// The [`BehaviourError`] that refused it.
    pub fn apply<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        action: &Action,
    ) -> Result<Applied, BehaviourError> {
        self.head.apply(driver, action)
    }

    /// Before frame `tick`: what the console sent through the link (see
    /// [`from_link`](Self::from_link)), the limit modes the behaviour asks
    /// for, then the queued commands (at most two), each logged with its
    /// answer, which goes to the console port that asked for it, if one did.
    pub fn drain<P: SetDutyCycle>(&mut self, driver: &mut FrameDriver<P>, tick: FrameTick) {
        self.from_link(driver, tick);
        match self.commands {
            Some(queue) => {
                let link = self.link;
                self.head
                    .drain_asked(driver, queue, |action, asker, outcome| {
                        log_outcome(tick.frame, "", action, outcome);
                        // The port that asked answers its line with it.
                        if let (Some(link), Some(asker)) = (link, asker) {
                            link.answer(asker, *outcome);
                        }
                    });
            }
            None => self.head.sync(driver),
        }
        if let Some(events) = self.show(driver, tick) {
            log_show(tick.frame, &events);
        }
    }

    /// Before frame `tick` (part of [`drain`](Self::drain)): the show
    /// layer's inputs from the show link, if linked ([`Head::show`]); the
    /// DMX signal as judged there is published to the link. What happened,
    /// for the log.
    pub fn show<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        tick: FrameTick,
    ) -> Option<ShowEvents> {
        let show = self.show?;
        // The frame task's clock, ms (wrapping): Bottango's curves are
        // timed on it.
        let curves = show.curves.sample(tick.ms);
        let events = self
            .head
            .show(driver, tick.at, Some(show.dmx.latest()), curves);
        if let Some(signal) = events.signal {
            show.dmx.set_signal(signal);
        }
        // The tracker's sighting (a radar's), if one came.
        let sighting = show.track.take();
        if let Some(event) =
            self.head
                .track(driver, tick.at, &show.track.settings(), sighting.as_ref())
        {
            log_track(tick.frame, event);
        }
        Some(events)
    }

    /// Before frame `tick`: the servo calibrations and the live behaviour
    /// settings (rest pose, relax, the look's duck) the console sent, if
    /// linked, each logged.
    pub fn from_link<P: SetDutyCycle>(&mut self, driver: &mut FrameDriver<P>, tick: FrameTick) {
        let Some(link) = self.link else {
            return;
        };
        if let Some(live) = link.take_live() {
            self.head.set_live(driver, &live);
            log::info!("frame {=u64}: rest and look settings changed", tick.frame);
        }
        for (axis, cal) in idle_head_core::Axis::ALL.iter().zip(link.take_servos()) {
            let Some(cal) = cal else { continue };
            match self.head.set_servo(driver, *axis, cal) {
                Ok(()) => log::info!(
                    "frame {=u64}: {=str} servo calibration changed",
                    tick.frame,
                    axis.name()
                ),
                // `{}` of the error, not its `message()`: the per-axis
                // message texts would take 2.5 KB of flash.
                Err(e) => log::warn!(
                    "frame {=u64}: {=str} servo calibration refused: {}",
                    tick.frame,
                    axis.name(),
                    e
                ),
            }
        }
    }

    /// After a frame that wrote `report`: the head's status for the
    /// console, if linked.
    pub fn publish<P: SetDutyCycle>(&self, driver: &FrameDriver<P>, report: &FrameReport) {
        if let Some(link) = self.link {
            let mode = HeadMode::of(
                driver.is_stopped(),
                driver.is_stopping(),
                self.head.rest_state(),
            );
            let mut status = HeadStatus::of(report, driver.stats(), mode, self.at);
            status.idle = Some(self.head.idle_view());
            if self.show.is_some_and(|show| show.track.settings().radar) {
                status.track = Some(self.head.track_view());
            }
            link.publish(status);
        }
    }

    /// Writes frame `tick`: idle, gaze and gestures mixed, through `driver`.
    /// The first call starts the driver (neutral pulses) instead. After a
    /// new rate's outputs were set ([`take_rate`](Self::take_rate)), the
    /// frames come its period apart from the next one on.
    ///
    /// This is the whole frame update (playback, mixer, fade, limits,
    /// mapping and the PWM writes), kept out of line so that it can be
    /// measured on its own.
    #[inline(never)]
    pub fn write<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        tick: FrameTick,
    ) -> HeadFrame {
        if tick.skipped > 0 {
            // The servos held their pulses through the frames missed.
            driver.held();
        }
        self.at = tick.at;
        let frame = self.head.frame(driver, tick.at);
        if let Some(period) = self.retime.pending.take() {
            self.retime_frames(driver, period);
        }
        frame
    }
}

/// Plays `frames` through `driver` until `hooks` says stop; the latest
/// wake-up after a deadline goes to `latest_wake_us` (µs, for the status
/// report).
///
/// The first frame is due at once and writes the neutral pose
/// ([`FrameDriver::start`]); the motion then fades in. Late frames and PWM
/// faults are logged (faults at most as often as the driver's fault policy
/// suggests).
pub async fn run<P, I, H>(
    driver: &mut FrameDriver<P>,
    frames: &mut FrameLoop<'_, I>,
    hooks: &mut H,
    latest_wake_us: &AtomicU32,
) -> RunStats
where
    P: SetPeriod,
    I: IdleSource,
    H: FrameHooks<P>,
{
    let mut max_lateness = 0;
    loop {
        let deadline = frames.deadline();
        Timer::at(Instant::from_ticks(deadline)).await;
        let woke = Instant::now().as_ticks();
        let tick = frames.next(woke);
        let lateness = woke.saturating_sub(deadline);
        if lateness > max_lateness {
            max_lateness = lateness;
            let us = Duration::from_ticks(lateness).as_micros();
            latest_wake_us.store(u32::try_from(us).unwrap_or(u32::MAX), Ordering::Relaxed);
        }
        if tick.skipped > 0 {
            log::warn!(
                "frame {=u64}: woke {=u64} us late, skipped {=u64} frame(s)",
                tick.frame,
                Duration::from_ticks(lateness).as_micros(),
                tick.skipped
            );
        }
        hooks.before_frame(&tick, driver);
        frames.drain(driver, tick);
        frames.take_rate(driver, tick);
        let HeadFrame { offsets, report } = frames.write(driver, tick);
        frames.publish(driver, &report);
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

/// Logs what the show layer's inputs did before frame `frame`: the DMX
/// signal's changes, the gestures its trigger fired.
fn log_show(frame: u64, events: &ShowEvents) {
    if let Some(signal) = events.signal {
        log::info!(
            "frame {=u64}: dmx: signal {=str}{=str}",
            frame,
            signal.as_str(),
            if signal == Signal::Lost {
                " (none for 1 s): the head plays on its own"
            } else {
                ""
            }
        );
    }
    if let Some((action, outcome)) = &events.fired {
        log_outcome(frame, "dmx ", action, outcome);
    }
}

/// Logs what the tracker did before frame `frame`.
fn log_track(frame: u64, event: TrackEvent) {
    match event {
        TrackEvent::Turned(yaw) => {
            log::info!("frame {=u64}: track: turned to yaw {}", frame, yaw);
        }
        TrackEvent::Released => {
            log::info!("frame {=u64}: track: nobody left, back to centre", frame);
        }
    }
}

/// Logs what `action` (from `via`: `""` for a console port or an input,
/// `"dmx "` for the DMX trigger) did before frame `frame`.
fn log_outcome(frame: u64, via: &str, action: &Action, outcome: &Result<Applied, BehaviourError>) {
    match outcome {
        Ok(applied) => log::info!(
            "frame {=u64}: {=str}{=str}: ok {}",
            frame,
            via,
            word(action),
            Started(applied)
        ),
        Err(e) => log::warn!(
            "frame {=u64}: {=str}{=str}: {}",
            frame,
            via,
            word(action),
            e
        ),
    }
}

fn log_faults(report: &FrameReport) {
    use idle_head_core::driver::Outcome;
    for (axis, servo) in idle_head_core::Axis::ALL.iter().zip(report.servos.iter()) {
        match servo.outcome {
            Outcome::Failed(kind) => log::warn!(
                "frame {=u64}: {=str} PWM write failed ({}); {=u32} fault(s) since the last report",
                report.frame,
                axis.name(),
                kind,
                report.unlogged_faults
            ),
            Outcome::Disabled(kind) => log::error!(
                "frame {=u64}: {=str} PWM keeps failing ({}): servo switched off",
                report.frame,
                axis.name(),
                kind
            ),
            Outcome::Written | Outcome::Off => {}
        }
    }
}

/// The command word of `action`, as the console spells it.
const fn word(action: &Action) -> &'static str {
    match action {
        Action::Gesture(request) => request.kind.name(),
        Action::Look(_) => "look",
        Action::Center { .. } => "center",
        Action::Idle(true) => "idle on",
        Action::Idle(false) => "idle off",
        Action::IdleAmp(_) => "idle amp",
        Action::Stop => "stop",
        Action::Rest => "rest",
        Action::Wake { .. } => "wake",
    }
}

/// What an action started, for the log: the resolved figures in the
/// user's units (the frame path's own fields left out).
// (Read by the log's formatting only, which the `defmt` feature brings.)
#[cfg_attr(not(feature = "defmt"), allow(dead_code))]
struct Started<'a>(&'a Applied);

#[cfg(feature = "defmt")]
impl defmt::Format for Started<'_> {
    // defmt keeps each text in a symbol of its own: arms that differ in
    // their text alone look the same to clippy.
    #[allow(clippy::match_same_arms)]
    fn format(&self, f: defmt::Formatter<'_>) {
        use idle_head_core::command::Hold;
        match self.0 {
            Applied::Gesture(plan) => {
                defmt::write!(
                    f,
                    "{=u8} cycle(s) of {} in {=u32} ms, intensity {=u8} %",
                    plan.cycles,
                    plan.amplitude,
                    plan.duration.0,
                    plan.intensity.get()
                );
            }
            Applied::Look(look) => {
                defmt::write!(
                    f,
                    "to pitch {} yaw {} in {=u32} ms",
                    look.pitch,
                    look.yaw,
                    look.duration.0
                );
                match look.hold {
                    Hold::Return(after) => defmt::write!(f, ", back after {=u32} ms", after.0),
                    Hold::Stay => defmt::write!(f, ", staying"),
                }
                if look.clamped {
                    defmt::write!(f, " (clamped to the limits)");
                }
            }
            Applied::Center(duration) => {
                defmt::write!(f, "back to centre in {=u32} ms", duration.0);
            }
            Applied::Idle(gain) => {
                defmt::write!(f, "idle to {=u8} %", gain.get());
            }
            Applied::Stop => {
                defmt::write!(f, "fading out");
            }
            Applied::Rest(duration) => {
                defmt::write!(f, "to the rest pose in {=u32} ms", duration.0);
            }
            Applied::Wake(duration) => {
                defmt::write!(f, "idle back in {=u32} ms", duration.0);
            }
        }
    }
}
