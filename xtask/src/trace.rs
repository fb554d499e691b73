//! `cargo xtask trace`: the firmware's frames simulated on the host, as CSV
//! (and PNG), for anyone to check.
//!
//! The core library's frame engine (`behaviour::Head`: the idle loops, the
//! behaviour mixer, the command queue, the frame driver) runs frame by frame
//! exactly as the frame task runs it on the board, with the built-in
//! configuration: the Table 2 loops (or the ones of `--seed`), 30 s loops,
//! 50 Hz frames, the default servos, driver and behaviour. A script's
//! motion commands go through the same queue at their times, its other
//! console lines through the console's service, its pin lines into the
//! input task's state machine (`host.rs`): the same core as the board's.
//! A line at a frame's time is taken before that frame.
//!
//! The CSV has one row per frame:
//!
//! ```text
//! frame,t_ms,pitch_mdeg,roll_mdeg,yaw_mdeg,pitch_ns,roll_ns,yaw_ns
//! ```
//!
//! the commanded angles after every safety stage (fade, speed and
//! acceleration limits, angle clamps) and the pulse widths of the duties
//! written, on PWM channels clocked as the Pico's (`idle_head_core::pwm_clock`:
//! 64 000 counts of 312.5 ns per 20 ms period).

mod host;
mod marks;
mod plot;
mod script;

use std::{fs, path::PathBuf};

use anyhow::{Context, Result, anyhow};
use idle_head_core::behaviour::{BehaviourConfig, CommandQueue, Head, LOOP_DURATION};
use idle_head_core::driver::{DriverConfig, FrameDriver};
use idle_head_core::idle::{GenerateOnTake, IdlePlayer, IdleTiming, LoopSet, LoopStream};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadConfig, Lcg};
use idle_head_core::{Axis, Playback};
use idle_head_firmware::config::IDLE_MODE;

use host::Origin;
use idle_head_core::behaviour::BehaviourParams;
use idle_head_core::console::{ConsoleLink, HeadMode, HeadStatus};
use idle_head_core::pwm_clock::{PICO_SERVO_CLOCK, PICO_SYS_HZ};
use marks::Mark;
pub use script::{Event, Kind};

/// A script's events (see `script.rs`), checked with `params`.
///
/// # Errors
/// Every bad line, each with its number and why.
pub fn parse_script(text: &str, params: &BehaviourParams) -> Result<Vec<Event>> {
    script::parse(text, params)
}

/// Options of `cargo xtask trace`.
#[derive(Debug, Clone, PartialEq, Eq, clap::Args)]
pub struct Args {
    /// Simulated time in seconds (decimals allowed: 2.5).
    #[arg(long = "seconds", value_name = "s", value_parser = positive_seconds)]
    pub micros: u64,
    /// Idle loops from seed n (pitch n, roll and yaw the next two values of
    /// the paper's LCG); default: the Table 2 loops.
    #[arg(long, value_name = "n")]
    pub seed: Option<u32>,
    /// The commands and their times, one per line: `<seconds> <command>`.
    #[arg(long, value_name = "file")]
    pub script: Option<PathBuf>,
    /// The CSV to write [default: trace/trace.csv in the target directory].
    #[arg(long, value_name = "csv")]
    pub out: Option<PathBuf>,
    /// Also draw the three axes over time, the commands marked, to this PNG
    /// [without a file: trace/trace.png in the target directory].
    #[arg(long, value_name = "file")]
    #[allow(clippy::option_option)] // absent, present without a value, with one
    pub png: Option<Option<PathBuf>>,
}

/// Where the trace goes without `--out` or a `--png` file: build output,
/// not the repository (`target/trace/` unless cargo is told otherwise).
fn default_dir() -> Result<PathBuf> {
    Ok(crate::project::metadata(&crate::project::root())?
        .target_dir
        .join("trace"))
}

/// `--seconds`: more than 0, in µs.
fn positive_seconds(text: &str) -> Result<u64, String> {
    match script::seconds(text) {
        Ok(0) => Err("must be more than 0".to_owned()),
        Ok(us) => Ok(us),
        Err(e) => Err(e.to_string()),
    }
}

/// One frame of the trace.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Row {
    /// Frame index.
    pub frame: u64,
    /// Time of the frame in ms.
    pub t_ms: u64,
    /// Commanded angles, m°.
    pub angles: [i32; 3],
    /// Pulse widths, ns.
    pub pulses: [u64; 3],
    /// The duties written, counts of the Pico's PWM (0: no pulse).
    pub duties: [u16; 3],
}

/// The simulated run.
pub struct Trace {
    /// One row per frame.
    pub rows: Vec<Row>,
    /// The script's commands as applied, and the looks' returns, in time
    /// order.
    pub marks: Vec<Mark>,
}

/// A PWM channel that keeps the last duty.
struct Channel(u16);

impl embedded_hal::pwm::ErrorType for Channel {
    type Error = core::convert::Infallible;
}

impl embedded_hal::pwm::SetDutyCycle for Channel {
    fn max_duty_cycle(&self) -> u16 {
        PICO_SERVO_CLOCK.top
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        self.0 = duty;
        Ok(())
    }
}

/// The idle loops' configuration for `seed` (or Table 2's).
fn config(seed: Option<u32>) -> HeadConfig {
    let mut config = DEFAULT_HEAD;
    if let Some(seed) = seed {
        let mut lcg = Lcg::new(seed);
        config.pitch.seed = seed;
        config.roll.seed = lcg.next_value();
        config.yaw.seed = lcg.next_value();
    }
    config
}

/// The firmware's idle source for `config`: its stream of loop sets
/// (never-repeating unless built with `fixed-loop`), each generated when
/// its join is due.
type Idle = IdlePlayer<Box<LoopSet<DEFAULT_N>>, GenerateOnTake<Box<LoopSet<DEFAULT_N>>, DEFAULT_N>>;

fn idle(config: HeadConfig, playback: Playback, seed: Option<u32>) -> Result<Idle> {
    let timing = IdleTiming::new(playback).map_err(|e| anyhow!("{}", e.message()))?;
    let mut stream = LoopStream::new(config, &timing);
    let mut first = Box::new(LoopSet::new());
    stream
        .next_into(&mut first)
        .map_err(|e| anyhow!("idle loops of seed {seed:?}: {e}"))?;
    let supply = GenerateOnTake::new(stream, Box::new(LoopSet::new()));
    Ok(IdlePlayer::new(first, supply, timing, IDLE_MODE))
}

/// Runs `micros` of frames with `events` (sorted by time): motion lines
/// through the queue, other console lines through the console's service,
/// pin lines into the input task ([`host`]).
pub fn simulate(micros: u64, seed: Option<u32>, events: &[Event]) -> Result<Trace> {
    let driver_params = DriverConfig::DEFAULT
        .build()
        .map_err(|e| anyhow!("{}", e.message()))?;
    let params = BehaviourConfig::DEFAULT
        .build(&driver_params)
        .map_err(|e| anyhow!("{e}"))?;
    let frame_us = u64::from(driver_params.config().frame_period.0);
    let count_ps = PICO_SERVO_CLOCK.count_ps(PICO_SYS_HZ);
    let playback = Playback::new(
        LOOP_DURATION,
        driver_params.config().frame_period,
        DEFAULT_N,
    )
    .map_err(|e| anyhow!("playback: {e:?}"))?;
    let idle = idle(config(seed), playback, seed)?;
    let mut head = Head::new(idle, params);
    let mut driver = FrameDriver::new([Channel(0), Channel(0), Channel(0)], driver_params);
    let queue: CommandQueue = CommandQueue::new();
    let link = ConsoleLink::new();
    let mut console = host::Console::new(&queue, &link)?;
    let mut task = host::Task::new(&link);

    let frames = micros / frame_us;
    let mut rows = Vec::with_capacity(usize::try_from(frames).unwrap_or(0));
    let mut marks = Vec::new();
    let mut next = 0;
    // Where each queued action came from, oldest first.
    let mut origins: Vec<Origin> = Vec::new();
    for frame in 0..frames {
        let t_us = frame * frame_us;
        let rest = head.rest_state();
        // The script's lines due, and the input task's wakes between them.
        while let Some(event) = events.get(next).filter(|e| e.at_us <= t_us) {
            wake_until(&mut task, event.at_us, rest, &link, &queue, &mut origins);
            let lines = Lines {
                queue: &queue,
                link: &link,
                origins: &mut origins,
            };
            if !lines.take(event, next, rest, &mut console, &mut task) {
                break;
            }
            next += 1;
        }
        wake_until(&mut task, t_us, rest, &link, &queue, &mut origins);
        // What the console sent through the link, then the queue.
        from_link(&link, &mut head, &mut driver, t_us);
        let mut taken = origins.drain(..).collect::<std::collections::VecDeque<_>>();
        head.drain(&mut driver, &queue, |action, outcome| {
            let Some(origin) = taken.pop_front() else {
                return;
            };
            let event = match origin {
                Origin::Line(i) => events[i].clone(),
                Origin::Other(text) => Event {
                    line: 0,
                    at_us: t_us,
                    text,
                    kind: Kind::Act(*action),
                },
            };
            marks.extend(marks::marks(&event, t_us / 1000, outcome, &params));
        });
        origins.extend(taken);
        let played = head.frame(&mut driver, frame);
        let report = played.report;
        let mode = HeadMode::of(driver.is_stopped(), driver.is_stopping(), head.rest_state());
        link.publish(HeadStatus::of(&report, driver.stats(), mode));
        let servos = report.servos;
        rows.push(Row {
            frame,
            t_ms: t_us / 1000,
            angles: servos.map(|s| s.angle.millidegrees()),
            pulses: servos.map(|s| (u64::from(s.duty.0) * count_ps + 500) / 1000),
            duties: servos.map(|s| s.duty.0),
        });
    }
    marks::settle(
        &mut marks,
        params.config().blend.0,
        frames * frame_us / 1000,
    );
    for event in &events[next..] {
        println!(
            "line {}: at {} s, after the trace's end: not run",
            event.line,
            script::show_seconds(event.at_us)
        );
    }
    Ok(Trace { rows, marks })
}

/// Where a script's lines go.
struct Lines<'a> {
    queue: &'a CommandQueue,
    link: &'a ConsoleLink,
    origins: &'a mut Vec<Origin>,
}

impl Lines<'_> {
    /// Takes `event` (the script's `index`-th) with the head in `rest`;
    /// `false` if it has to wait for the next frame (the queue is full).
    fn take(
        self,
        event: &Event,
        index: usize,
        rest: idle_head_core::behaviour::RestState,
        console: &mut host::Console<'_>,
        task: &mut host::Task,
    ) -> bool {
        match event.kind {
            Kind::Act(action) => {
                if self.queue.try_submit(action).is_err() {
                    // A console would be told `err busy`; the script waits.
                    println!(
                        "line {}: command queue full at {} ms, `{}` waits a frame",
                        event.line,
                        event.at_us / 1000,
                        event.text
                    );
                    return false;
                }
                self.origins.push(Origin::Line(index));
            }
            Kind::Console => {
                let (reply, queued) = console.line(&event.text);
                println!("{:>9} ms  {}: {reply}", event.at_us / 1000, event.text);
                if queued {
                    self.origins.push(Origin::Other(event.text.clone()));
                }
                // The input task takes new settings at once.
                task.wake(event.at_us, rest, self.link, self.queue, self.origins);
            }
            Kind::Pin { input, high } => {
                task.drive(input, high);
                task.wake(event.at_us, rest, self.link, self.queue, self.origins);
            }
        }
        true
    }
}

/// Between frames: the live settings and calibrations the console sent.
fn from_link<I: idle_head_core::behaviour::IdleSource>(
    link: &ConsoleLink,
    head: &mut Head<I>,
    driver: &mut FrameDriver<Channel>,
    t_us: u64,
) {
    if let Some(live) = link.take_live() {
        head.set_live(driver, &live);
    }
    for (axis, cal) in Axis::ALL.iter().zip(link.take_servos()) {
        if let Some(cal) = cal
            && let Err(e) = head.set_servo(driver, *axis, cal)
        {
            println!(
                "{} ms: {} servo calibration refused: {e}",
                t_us / 1000,
                axis.name()
            );
        }
    }
}

/// The input task's wakes at its deadlines up to `until` µs.
fn wake_until(
    task: &mut host::Task,
    until: u64,
    rest: idle_head_core::behaviour::RestState,
    link: &ConsoleLink,
    queue: &CommandQueue,
    origins: &mut Vec<Origin>,
) {
    while let Some(at) = task.deadline().filter(|&at| at <= until) {
        task.wake(at, rest, link, queue, origins);
        if task.deadline() == Some(at) {
            break;
        }
    }
}

/// `cargo xtask trace`.
pub fn command(args: &Args) -> Result<bool> {
    let driver_params = DriverConfig::DEFAULT
        .build()
        .map_err(|e| anyhow!("{}", e.message()))?;
    let params = BehaviourConfig::DEFAULT
        .build(&driver_params)
        .map_err(|e| anyhow!("{e}"))?;
    let events = match &args.script {
        Some(path) => {
            let text = fs::read_to_string(path)
                .with_context(|| format!("reading the script {}", path.display()))?;
            script::parse(&text, &params).map_err(|e| anyhow!("{}: {e}", path.display()))?
        }
        None => Vec::new(),
    };
    let trace = simulate(args.micros, args.seed, &events)?;
    let out = match &args.out {
        Some(out) => out.clone(),
        None => default_dir()?.join("trace.csv"),
    };
    write_csv(&trace, &out)?;
    for mark in &trace.marks {
        println!("{:>9} ms  {}", mark.t_ms, mark.reply);
    }
    summary(&trace);
    println!("wrote {} ({} frames)", out.display(), trace.rows.len());
    if let Some(png) = &args.png {
        let png = match png {
            Some(png) => png.clone(),
            None => default_dir()?.join("trace.png"),
        };
        plot::draw(&trace, args.seed, &png)?;
        println!("wrote {}", png.display());
    }
    Ok(true)
}

fn write_csv(trace: &Trace, path: &std::path::Path) -> Result<()> {
    use std::fmt::Write as _;
    let mut csv =
        String::from("frame,t_ms,pitch_mdeg,roll_mdeg,yaw_mdeg,pitch_ns,roll_ns,yaw_ns\n");
    for row in &trace.rows {
        let [p, r, y] = row.angles;
        let [pn, rn, yn] = row.pulses;
        let _ = writeln!(csv, "{},{},{p},{r},{y},{pn},{rn},{yn}", row.frame, row.t_ms);
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    fs::write(path, csv).with_context(|| format!("writing {}", path.display()))
}

/// Range, largest step and largest change of step per axis.
fn summary(trace: &Trace) {
    for (i, axis) in Axis::ALL.iter().enumerate() {
        let values: Vec<i64> = trace.rows.iter().map(|r| i64::from(r.angles[i])).collect();
        let (lo, hi) = values
            .iter()
            .fold((i64::MAX, i64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let step = values
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .max()
            .unwrap_or(0);
        let turn = values
            .windows(3)
            .map(|w| (w[2] - 2 * w[1] + w[0]).abs())
            .max()
            .unwrap_or(0);
        let pulses = trace.rows.iter().map(|r| r.pulses[i]);
        let (plo, phi) = pulses.fold((u64::MAX, 0), |(lo, hi), p| (lo.min(p), hi.max(p)));
        println!(
            "{:<5} angle {lo}..{hi} mdeg, largest step {step} mdeg/frame, largest change of step {turn} mdeg/frame², pulses {plo}..{phi} ns",
            axis.name()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(script: &str, seconds: u64) -> Trace {
        let driver = DriverConfig::DEFAULT.build().unwrap();
        let params = BehaviourConfig::DEFAULT.build(&driver).unwrap();
        let events = script::parse(script, &params).unwrap();
        simulate(seconds * 1_000_000, None, &events).unwrap()
    }

    #[test]
    fn idle_only_is_the_plain_frame_loop() {
        // No script: the same pulses as the driver fed by the playback alone.
        let trace = run("", 3);
        assert_eq!(trace.rows.len(), 150);
        // The first frame: neutral pulses, 1500 µs as 4800 counts of 312.5 ns.
        assert_eq!(trace.rows[0].angles, [0; 3]);
        assert_eq!(trace.rows[0].pulses, [1_500_000; 3]);
        let driver = DriverConfig::DEFAULT.build().unwrap();
        let playback =
            Playback::new(LOOP_DURATION, driver.config().frame_period, DEFAULT_N).unwrap();
        let mut source = idle(config(None), playback, None).unwrap();
        let mut plain = FrameDriver::new([Channel(0), Channel(0), Channel(0)], driver);
        for row in &trace.rows {
            let report = plain.write_frame(source.offsets(row.frame));
            assert_eq!(row.angles, report.servos.map(|s| s.angle.millidegrees()));
        }
    }

    #[test]
    fn a_looks_return_is_marked_where_the_head_goes_back() {
        // The idle motion off (it fades out in 1 s): only the gaze moves.
        let trace = run("0 idle off\n2 look 10000 0 500 hold=1000\n", 6);
        let back: Vec<&Mark> = trace
            .marks
            .iter()
            .filter(|m| m.kind == marks::Kind::Return)
            .collect();
        assert_eq!(back.len(), 1, "{:?}", trace.marks);
        let back = back[0];
        // 500 ms there, the 1 s hold, then back.
        assert_eq!(back.t_ms, 3500);
        assert_eq!(back.axes, [Axis::Pitch, Axis::Yaw]);
        let pitch = |t_ms: u64| trace.rows[usize::try_from(t_ms / 20).unwrap()].angles[0];
        assert_eq!(pitch(back.t_ms - 20), 10_000);
        assert_eq!(pitch(back.t_ms), 10_000);
        assert!(pitch(back.t_ms + 20) < 10_000);
        assert!(pitch(back.t_ms + back.span_ms - 20) > 0);
        assert_eq!(pitch(back.t_ms + back.span_ms), 0);
        assert_eq!(
            back.reply,
            format!(
                "(the look at line 2 returns to the centre after its 1000 ms hold, in {} ms)",
                back.span_ms
            )
        );
        // The marks are in time order.
        assert!(trace.marks.windows(2).all(|w| w[0].t_ms <= w[1].t_ms));
    }

    #[test]
    fn a_return_is_cut_or_left_out_by_the_next_gaze_move() {
        let returns = |script: &str| -> Vec<(u64, u64)> {
            run(script, 8)
                .marks
                .iter()
                .filter(|m| m.kind == marks::Kind::Return)
                .map(|m| (m.t_ms, m.span_ms))
                .collect()
        };
        let look = "2 look 10000 0 500 hold=1000\n";
        let whole = returns(look);
        assert_eq!(whole.len(), 1);
        assert!(whole[0].1 > 100);
        // A center before the return starts: there is none.
        assert_eq!(returns(&format!("{look}3 center\n")), []);
        // Another look while it plays: it ends there.
        assert_eq!(
            returns(&format!("{look}3.6 look 0 5000 hold=stay\n")),
            [(3500, 100)]
        );
        // A nod does not touch it; a return after the end is left out.
        assert_eq!(returns(&format!("{look}3.6 nod\n")), whole);
        assert_eq!(returns("7.5 look 10000 0 500 hold=1000\n"), []);
    }

    #[test]
    fn a_scripted_nod_moves_pitch_only_and_answers() {
        let idle = run("", 6);
        let nodding = run("3 nod 6000 800\n", 6);
        assert_eq!(nodding.marks.len(), 1);
        assert_eq!(
            nodding.marks[0].reply,
            "ok nod 6000 mdeg 2 cycles 800 ms intensity 50"
        );
        let frame = |t: &Trace, k: usize| t.rows[k].angles;
        for k in 0..300 {
            let (a, b) = (frame(&idle, k), frame(&nodding, k));
            assert_eq!((a[1], a[2]), (b[1], b[2]), "frame {k}");
            if !(150..230).contains(&k) {
                assert_eq!(a[0], b[0], "frame {k}");
            }
        }
        // The first dip (10 frames from 149, the last frame mixed before
        // the nod) is the nod's 6°, over the idle ducked by 60 %.
        let dip = frame(&nodding, 159)[0] - frame(&idle, 159)[0];
        let ducked = -frame(&idle, 159)[0] * 6 / 10;
        assert!(
            (dip - 6000 - ducked).abs() <= 3,
            "{dip}, ducked by {ducked}"
        );
    }

    /// The idle limits of the built-in driver per 20 ms frame: 60 °/s,
    /// 600 °/s².
    const IDLE_STEP: i32 = 1200;
    const IDLE_TURN: i32 = 240;

    #[test]
    fn a_presence_script_rests_relaxes_wakes_and_glances() {
        let trace = run(
            "\
0 input 2 presence -20000
0 rest after 5
0 rest relax on
12 pin 2 high
16 pin 2 low
",
            20,
        );
        let at = |ms: u64| trace.rows[usize::try_from(ms / 20).unwrap()];
        // Rested 5 s in, there after the 3 s glide: the pose held, the
        // pulses off.
        for ms in (8020..12060).step_by(20) {
            assert_eq!(at(ms).angles, [-8000, 0, 0], "{ms} ms");
            assert_eq!(at(ms).pulses, [0; 3], "{ms} ms");
        }
        assert!(at(7980).pulses.iter().all(|&p| p > 0));
        // Woken by the sensor 50 ms after its edge: the first pulse is the
        // last before the gap, and the idle comes back within the idle
        // limits until the glance starts, a second later.
        assert_eq!(at(12_060).pulses, at(7980).pulses);
        let wake: Vec<[i32; 3]> = (12_040..=13_060)
            .step_by(20)
            .map(|ms| at(ms).angles)
            .collect();
        for axis in 0..3 {
            let v: Vec<i32> = wake.iter().map(|a| a[axis]).collect();
            let step = v.windows(2).map(|w| (w[1] - w[0]).abs()).max().unwrap();
            let turn = v
                .windows(3)
                .map(|w| (w[2] - 2 * w[1] + w[0]).abs())
                .max()
                .unwrap();
            assert!(
                step <= IDLE_STEP && turn <= IDLE_TURN,
                "axis {axis}: {step} {turn}"
            );
        }
        assert_ne!(at(13_060).angles, [-8000, 0, 0]);
        // Then the glance towards the sensor: yaw at −20° (the idle's
        // ducked sway aside), held about 2 s, then back.
        let near = |ms: u64| (at(ms).angles[2] + 20_000).abs() < 2500;
        let held: Vec<u64> = (13_000..17_000)
            .step_by(20)
            .filter(|&ms| near(ms))
            .collect();
        assert!(held.len() >= 100, "{} frames near -20°", held.len());
        assert!(!near(19_000));
        let wake = trace
            .marks
            .iter()
            .find(|m| m.reply.starts_with("ok wake"))
            .unwrap();
        assert_eq!(
            (wake.t_ms, wake.reply.as_str()),
            (12_060, "ok wake 1000 ms")
        );
    }

    #[test]
    fn a_button_runs_its_action_within_a_frame_of_its_debounced_edge() {
        let trace = run("0 input 3 button nod 6000\n3 pin 3 low\n", 5);
        let nod = trace.marks.iter().find(|m| m.label == "inputs:").unwrap();
        // Pressed at 3 s, debounced at 3.005 s, taken at the next frame,
        // which is already a step into the nod.
        assert_eq!(nod.t_ms, 3020);
        assert!(nod.reply.starts_with("ok nod 6000 mdeg"), "{}", nod.reply);
        let idle = run("", 5);
        let first = (150..250).find(|&k| trace.rows[k].angles[0] != idle.rows[k].angles[0]);
        assert_eq!(first, Some(151));
    }
}
