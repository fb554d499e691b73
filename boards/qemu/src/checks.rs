//! The smoke run's schedule (fault injection, stop) and invariant checks,
//! as the frame task's hooks.
//!
//! Frame indices below are frames of the time-compressed run, which are the
//! Pico's 50 Hz frames one for one (see the crate docs): frame 1500 is 30 s
//! into the loop on the board. The first join blends the next loop set in
//! over frames 1400..1500.

use core::ops::Range;
use core::sync::atomic::Ordering;

use idle_head_core::behaviour::CommandQueue;
use idle_head_core::driver::{DriverConfig, FrameDriver, FrameTick, Outcome};
use idle_head_core::idle::IdleStats;
use idle_head_core::{Angle, Axis};
use idle_head_firmware::config::{DEFAULT_PARAMS, DEFAULT_TIMING};
use idle_head_firmware::frame::{Flow, Frame, FrameHooks, RunStats};

use crate::pwm::VirtualPwm;
use crate::script;

/// Frames per loop: 1.5 s / 1 ms (= 30 s / 20 ms on the Pico).
pub const LOOP_FRAMES: u64 = crate::LOOP.0 as u64 * 1000 / crate::FRAME_PERIOD.0 as u64;
/// The Pico's frame period, µs: frame `k` here plays the Pico's frame `k`.
const PICO_FRAME_US: u64 = crate::CONFIG.frame_period.0 as u64;
/// The first join: the frames where loop set 0 blends into loop set 1.
const JOIN: Range<u64> = DEFAULT_TIMING.period_us() / PICO_FRAME_US
    ..(DEFAULT_TIMING.period_us() + DEFAULT_TIMING.join_us) / PICO_FRAME_US;
/// Fade-in frames (the soft start).
const FADE_FRAMES: u64 = DEFAULT_PARAMS.fade_frames() as u64;
/// A trace line every 50 frames (1 s on the Pico) for the host's plot.
const TRACE_EVERY: u64 = 50;

/// Frames a servo left outside new angle limits may take to come back:
/// the widest span (720°) at the slowest limiter (60 °/s, 600 °/s²) takes
/// 12 s, 600 frames.
const RETURN_FRAMES: u64 = 650;

/// The servo whose PWM output gets the injected faults.
const FAULTY: Axis = Axis::Yaw;
/// A burst of failed writes shorter than the disable threshold: counted,
/// logged, survived. Starts after one whole loop at full gain (frames
/// `FADE_FRAMES..FADE_FRAMES + LOOP_FRAMES` = 100..1600).
const BURST: Range<u64> = 1650..1660;
/// From here on every write fails: the servo is switched off after
/// `disable_after` (0.5 s: 25) failed frames in a row, at frame 1724.
const PERSISTENT_FROM: u64 = 1700;
/// Fade-out (soft stop) requested here; it takes `FADE_FRAMES` frames.
const STOP_AT: u64 = 1800;
/// Frames played after the fade-out has finished.
const TAIL: u64 = 2;

const _: () = {
    assert!(
        BURST.start >= FADE_FRAMES + LOOP_FRAMES,
        "faults only after a whole loop"
    );
    assert!(((BURST.end - BURST.start) as u16) < DEFAULT_PARAMS.disable_frames());
    assert!(BURST.end < PERSISTENT_FROM);
    assert!(PERSISTENT_FROM + (DEFAULT_PARAMS.disable_frames() as u64) < STOP_AT);
    assert!(
        script::QUIET_FROM <= JOIN.start,
        "the script's motion ends before the join"
    );
};

/// Faults the schedule injects: the burst, then the failed frames up to the
/// switch-off.
const EXPECTED_FAULTS: u32 =
    (BURST.end - BURST.start) as u32 + DEFAULT_PARAMS.disable_frames() as u32;

/// Largest frame-to-frame change of the offsets (velocity, d1) and of that
/// change (acceleration, d2), per axis: inside the loops (the script's frames
/// left out), over the join (its frames and the frame after), and while the
/// script plays.
#[derive(Clone, Copy, Default)]
struct Steps {
    inside: [[u32; 3]; 2],
    join: [[u32; 3]; 2],
    /// While the script plays (not compared).
    scripted: [[u32; 3]; 2],
}

/// Hooks of the smoke run: schedule, frame log, invariants.
pub struct Checks {
    config: DriverConfig,
    /// Where the script's commands go (the frame loop drains it).
    commands: &'static CommandQueue,
    /// The fade-out waits for the console's host to hang up.
    hold: bool,
    failures: u32,
    previous: Option<Frame>,
    /// The last frame's offset steps (d1), for d2.
    last_steps: Option<[i32; 3]>,
    steps: Steps,
    /// Frames after the first fault in which pitch or roll moved.
    others_moved: [u32; 3],
    disabled_at: Option<u64>,
    stopped_at: Option<u64>,
    stop_requested: bool,
    last: u64,
    /// The frame of each servo's last calibration change (from the console).
    recalibrated: [Option<u64>; 3],
    /// SysTick count when the current frame's write began.
    write_started: u64,
    /// Largest and total SysTick counts of the frame writes.
    write_counts: (u64, u64),
}

impl Checks {
    pub const fn new(config: DriverConfig, commands: &'static CommandQueue, hold: bool) -> Self {
        Self {
            config,
            commands,
            hold,
            failures: 0,
            previous: None,
            last_steps: None,
            steps: Steps {
                inside: [[0; 3]; 2],
                join: [[0; 3]; 2],
                scripted: [[0; 3]; 2],
            },
            others_moved: [0; 3],
            disabled_at: None,
            stopped_at: None,
            stop_requested: false,
            last: 0,
            recalibrated: [None; 3],
            write_started: 0,
            write_counts: (0, 0),
        }
    }

    fn fail(&mut self) {
        self.failures += 1;
    }

    /// The end-of-run checks; `true` if every invariant held.
    pub fn finish(
        &mut self,
        stats: &RunStats,
        idle: &IdleStats,
        driver: &mut FrameDriver<VirtualPwm>,
        generated: bool,
    ) -> bool {
        if !generated {
            self.fail();
        }
        if stats.missed != 0 {
            defmt::error!("check: {=u64} frame(s) missed", stats.missed);
            self.fail();
        }
        // One whole loop at full gain: from the end of the fade-in past the
        // next loop boundary.
        if self.last < FADE_FRAMES + LOOP_FRAMES {
            defmt::error!(
                "check: only {=u64} frames played, less than a whole loop",
                self.last
            );
            self.fail();
        }
        // A held run plays on past the first join.
        let joins_ok = if self.hold {
            idle.joins >= 1 && idle.set == idle.joins
        } else {
            idle.joins == 1 && idle.set == 1
        };
        if !joins_ok || idle.late != 0 {
            defmt::error!("check: want one join on time, to loop set 1");
            self.fail();
        }
        // The join as smooth as the loops: no larger step than anywhere
        // inside them, and a change of step within twice theirs (the frames
        // over the join mix the two loops' accelerations, a few m° per frame
        // per frame, counted in whole m°). A jump or a kink at the join
        // would stand out many times over.
        for axis in Axis::ALL {
            let i = axis.index();
            let [inside, join, scripted] =
                [self.steps.inside, self.steps.join, self.steps.scripted];
            defmt::info!(
                "{=str}: largest offset step {=u32} mdeg and change of step {=u32} mdeg inside the loops, {=u32} and {=u32} over the join, {=u32} and {=u32} under the script",
                axis.name(),
                inside[0][i],
                inside[1][i],
                join[0][i],
                join[1][i],
                scripted[0][i],
                scripted[1][i]
            );
            if join[0][i] > inside[0][i] || join[1][i] > 2 * inside[1][i] {
                defmt::error!("check: {=str} is rougher at the join", axis.name());
                self.fail();
            }
        }
        let driver_stats = *driver.stats();
        let faults: u32 = driver_stats.faults.iter().sum();
        let want_disabled = Axis::ALL.map(|a| a == FAULTY);
        if faults != EXPECTED_FAULTS
            || driver_stats.faults[FAULTY.index()] != EXPECTED_FAULTS
            || driver_stats.disabled != want_disabled
        {
            defmt::error!(
                "check: faults {} disabled {}, want {=u32} on {=str} and only it disabled",
                driver_stats.faults,
                driver_stats.disabled,
                EXPECTED_FAULTS,
                FAULTY.name()
            );
            self.fail();
        }
        let want_at = PERSISTENT_FROM + DEFAULT_PARAMS.disable_frames() as u64 - 1;
        if self.disabled_at != Some(want_at) {
            defmt::error!(
                "check: {=str} not switched off at frame {=u64}",
                FAULTY.name(),
                want_at
            );
            self.fail();
        }
        for axis in Axis::ALL.into_iter().filter(|&a| a != FAULTY) {
            let moved = self.others_moved[axis.index()];
            defmt::info!(
                "{=str} moved in {=u32} of the frames after the first injected fault",
                axis.name(),
                moved
            );
            if moved == 0 {
                defmt::error!(
                    "check: {=str} stopped moving during the faults",
                    axis.name()
                );
                self.fail();
            }
        }
        for (axis, channel) in Axis::ALL.iter().zip(driver.channels_mut().iter()) {
            let log = channel.log();
            defmt::info!(
                "{=str} output: {=u32} writes accepted, {=u32} rejected, {=u32} violations, now {=u64} ns pulses",
                axis.name(),
                log.accepted,
                log.rejected,
                log.violations,
                channel.pulse_ns(log.current)
            );
        }
        let insns = crate::systick::INSNS_PER_COUNT;
        defmt::info!(
            "frame work: {=u64} instructions on average, at most {=u64} (fault log included)",
            self.write_counts.1 * insns / stats.frames.max(1),
            self.write_counts.0 * insns
        );
        if self.stopped_at.is_none() {
            defmt::error!("check: the fade-out never finished");
            self.fail();
        }
        self.failures == 0
    }

    /// Per-frame checks of the driver's own report.
    fn check_frame(&mut self, frame: &Frame, driver: &mut FrameDriver<VirtualPwm>) {
        let index = frame.tick.frame;
        if frame.tick.skipped != 0 {
            self.fail(); // also counted in `missed`; the run logs it
        }
        // The calibrations as they are now: the console may change them.
        let servos = driver.params().config().servos;
        for (((known, at), cal), channel) in self
            .config
            .servos
            .iter_mut()
            .zip(&mut self.recalibrated)
            .zip(&servos)
            .zip(driver.channels_mut().iter_mut())
        {
            if known != cal {
                *known = *cal;
                *at = Some(index);
                // The outputs judge the next pulses by the new range.
                channel.judge(cal);
            }
        }
        let report = frame
            .report
            .servos
            .iter()
            .zip(&servos)
            .zip(self.recalibrated);
        for (i, ((servo, cal), recalibrated)) in report.enumerate() {
            if servo.outcome != Outcome::Written {
                continue;
            }
            // Pulse limits are hard. New angle limits may leave a servo
            // outside them; the limiter brings it back in within
            // `RETURN_FRAMES`.
            let returning = recalibrated.is_some_and(|at| index <= at + RETURN_FRAMES);
            if servo.pulse < cal.min_pulse
                || servo.pulse > cal.max_pulse
                || (!cal.limits.contains(servo.angle) && !returning)
            {
                defmt::error!(
                    "check: frame {=u64}: {=str} at {} = {=u32} us, outside its limits",
                    index,
                    Axis::ALL[i].name(),
                    Deg(servo.angle),
                    servo.pulse.0
                );
                self.fail();
            }
        }
        if index == 0 {
            // Soft start: the very first pulse of every output is its
            // neutral pulse, and nothing was written before this frame.
            for (i, channel) in driver.channels_mut().iter().enumerate() {
                let log = channel.log();
                let neutral_ns = u64::from(self.config.servos[i].neutral.0) * 1000;
                let first_ns = log.first.map_or(0, |d| channel.pulse_ns(d));
                // Within one count (305 ns) of the neutral pulse.
                if log.accepted != 1 || first_ns.abs_diff(neutral_ns) > 400 {
                    defmt::error!(
                        "check: {=str}: first pulse {=u64} ns after {=u32} writes, want neutral {=u64} ns",
                        Axis::ALL[i].name(),
                        first_ns,
                        log.accepted,
                        neutral_ns
                    );
                    self.fail();
                }
            }
        }
        if let Some(previous) = &self.previous {
            let join = usize::from((JOIN.start..=JOIN.end).contains(&index));
            let after_fault = index >= BURST.start;
            let steps: [i32; 3] = core::array::from_fn(|i| {
                frame.offsets[i].millidegrees() - previous.offsets[i].millidegrees()
            });
            // The script's gestures and look are not the idle's steps: the
            // loops' own are measured outside them.
            let scripted = (script::SCRIPT[0].frame..script::QUIET_FROM).contains(&index);
            let slots = if join == 1 {
                &mut self.steps.join
            } else if scripted {
                &mut self.steps.scripted
            } else {
                &mut self.steps.inside
            };
            for i in 0..3 {
                slots[0][i] = slots[0][i].max(steps[i].unsigned_abs());
                if let Some(last) = self.last_steps {
                    slots[1][i] = slots[1][i].max(steps[i].abs_diff(last[i]));
                }
                if after_fault && frame.report.servos[i].angle != previous.report.servos[i].angle {
                    self.others_moved[i] += 1;
                }
            }
            self.last_steps = Some(steps);
        }
    }
}

impl FrameHooks<VirtualPwm> for Checks {
    fn before_frame(&mut self, tick: &FrameTick, driver: &mut FrameDriver<VirtualPwm>) {
        let inject = BURST.contains(&tick.frame) || tick.frame >= PERSISTENT_FROM;
        let index = FAULTY.index();
        if tick.frame == BURST.start {
            defmt::info!(
                "frame {=u64}: injecting PWM write errors on {=str} for {=u64} frames",
                tick.frame,
                FAULTY.name(),
                BURST.end - BURST.start
            );
        } else if tick.frame == BURST.end {
            defmt::info!(
                "frame {=u64}: {=str} PWM writes succeed again",
                tick.frame,
                FAULTY.name()
            );
        } else if tick.frame == PERSISTENT_FROM {
            defmt::info!(
                "frame {=u64}: every {=str} PWM write fails from now on",
                tick.frame,
                FAULTY.name()
            );
        }
        if let Some(channel) = driver.channels_mut().get_mut(index) {
            channel.inject_faults(inject);
        }
        if let Err(full) = script::submit(tick.frame, self.commands) {
            defmt::error!("check: frame {=u64}: {}", tick.frame, full.0);
            self.fail();
        }
        self.write_started = crate::systick::now_counts();
    }

    fn after_frame(&mut self, frame: &Frame, driver: &mut FrameDriver<VirtualPwm>) -> Flow {
        // Cost of the frame's work (interpolation, driver, PWM writes, fault
        // log): between the two hooks. Logged frames cost more than others.
        let spent = crate::systick::now_counts() - self.write_started;
        self.write_counts = (self.write_counts.0.max(spent), self.write_counts.1 + spent);
        let index = frame.tick.frame;
        self.last = index;
        self.check_frame(frame, driver);

        if frame.report.disabled > 0 {
            self.disabled_at = Some(index);
        }
        let stopping_now = self.stopped_at.is_none() && driver.is_stopped();
        let join_start = JOIN.start - 2..=JOIN.start + 2;
        let join_end = JOIN.end - 2..=JOIN.end + 2;
        if index <= 2
            || join_start.contains(&index)
            || join_end.contains(&index)
            || index.is_multiple_of(TRACE_EVERY)
            || frame.report.failed > 0 && frame.report.should_log
            || index == BURST.end
            || self.stopped_at.is_some()
            || stopping_now
        {
            log_frame(frame);
        }
        if index == JOIN.start {
            defmt::info!(
                "frame {=u64}: join: the next loop set blends in over {=u64} frames",
                index,
                JOIN.end - JOIN.start
            );
        } else if index == JOIN.end {
            defmt::info!("frame {=u64}: join done: the new loop set plays on", index);
        }
        let released = !self.hold || crate::console::HUNG_UP.load(Ordering::Acquire);
        if index >= STOP_AT && released && !self.stop_requested {
            defmt::info!("frame {=u64}: fading out", index);
            driver.request_stop();
            self.stop_requested = true;
        }
        if stopping_now {
            defmt::info!("frame {=u64}: fade-out done, at the neutral pose", index);
            self.stopped_at = Some(index);
        }
        if let Some(at) = self.stopped_at
            && index >= at + TAIL
        {
            for (i, servo) in frame.report.servos.iter().enumerate() {
                if servo.outcome == Outcome::Written && servo.angle != self.config.neutral_pose[i] {
                    defmt::error!(
                        "check: {=str} not back at its neutral pose",
                        Axis::ALL[i].name()
                    );
                    self.fail();
                }
            }
            return Flow::Stop;
        }
        self.previous = Some(*frame);
        Flow::Continue
    }
}

/// One readable frame line: index, commanded angles, pulses.
fn log_frame(frame: &Frame) {
    let [p, r, y] = frame.report.servos;
    let written = frame
        .report
        .servos
        .iter()
        .all(|s| s.outcome == Outcome::Written);
    if written {
        defmt::info!(
            "frame {=u64}: pitch={} roll={} yaw={} deg, pulses {=u32} {=u32} {=u32} us",
            frame.tick.frame,
            Deg(p.angle),
            Deg(r.angle),
            Deg(y.angle),
            p.pulse.0,
            r.pulse.0,
            y.pulse.0
        );
    } else {
        defmt::info!(
            "frame {=u64}: pitch={} roll={} yaw={} deg, pulses {=u32} {=u32} {=u32} us ({} {} {})",
            frame.tick.frame,
            Deg(p.angle),
            Deg(r.angle),
            Deg(y.angle),
            p.pulse.0,
            r.pulse.0,
            y.pulse.0,
            p.outcome,
            r.outcome,
            y.outcome
        );
    }
}

/// An angle shown in degrees with three decimals (`-1.234`).
struct Deg(Angle);

impl defmt::Format for Deg {
    fn format(&self, f: defmt::Formatter<'_>) {
        let m = self.0.millidegrees();
        let sign = if m < 0 { "-" } else { "+" };
        let abs = m.unsigned_abs();
        defmt::write!(f, "{=str}{=u32}.{=u32:03}", sign, abs / 1000, abs % 1000);
    }
}
