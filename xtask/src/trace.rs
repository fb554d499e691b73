//! `cargo xtask trace`: the firmware's frames simulated on the host, as CSV
//! (and PNG), for anyone to check.
//!
//! The core library's frame engine (`behaviour::Head`: the idle loops, the
//! behaviour mixer, the command queue, the frame driver) runs frame by frame
//! exactly as the frame task runs it on the board, with the built-in
//! configuration: the Table 2 loops (or the ones of `--seed`), 30 s loops,
//! 50 Hz frames, the default servos, driver and behaviour. A script's
//! commands go through the same queue at their times.
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

mod plot;
mod script;

use std::{fs, path::PathBuf};

use anyhow::{Context, Result, anyhow};
use idle_head_core::behaviour::{Applied, BehaviourConfig, CommandQueue, Head, LOOP_DURATION};
use idle_head_core::command::GestureKind;
use idle_head_core::driver::{DriverConfig, FrameDriver};
use idle_head_core::idle::{GenerateOnTake, IdlePlayer, IdleTiming, LoopSet, LoopStream};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadConfig, Lcg};
use idle_head_core::{Axis, Playback};
use idle_head_firmware::frame::IDLE_MODE;

use idle_head_core::pwm_clock::{PICO_SERVO_CLOCK, PICO_SYS_HZ};
use script::Event;

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
    /// The CSV to write.
    #[arg(long, value_name = "csv", default_value = "trace.csv")]
    pub out: PathBuf,
    /// Also draw the three axes over time, the commands marked, to this PNG.
    #[arg(long, value_name = "file")]
    pub png: Option<PathBuf>,
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
}

/// What a script command did, for the summary and the plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// When it was applied, in ms.
    pub t_ms: u64,
    /// How long its motion lasts, in ms (0: a switch).
    pub span_ms: u64,
    /// The axes it moves.
    pub axes: Vec<Axis>,
    /// A short label (`nod`, `look clamped`, ...).
    pub label: String,
    /// The reply a console would give.
    pub reply: String,
}

/// The simulated run.
pub struct Trace {
    /// One row per frame.
    pub rows: Vec<Row>,
    /// The script's commands as applied.
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

/// Runs `micros` of frames with `events` (sorted by time).
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

    let frames = micros / frame_us;
    let mut rows = Vec::with_capacity(usize::try_from(frames).unwrap_or(0));
    let mut marks = Vec::new();
    let mut pending = events.iter().peekable();
    // Which line each queued action came from, oldest first.
    let mut queued: std::collections::VecDeque<&Event> = std::collections::VecDeque::new();
    for frame in 0..frames {
        let t_us = frame * frame_us;
        while let Some(event) = pending.next_if(|e| e.at_us <= t_us) {
            if queue.try_submit(event.action).is_err() {
                // A console would be told `err busy`; the script waits.
                println!(
                    "line {}: command queue full at {} ms, `{}` waits a frame",
                    event.line,
                    t_us / 1000,
                    event.text
                );
                break;
            }
            queued.push_back(event);
        }
        head.drain(&mut driver, &queue, |action, outcome| {
            let Some(event) = queued.pop_front() else {
                return;
            };
            debug_assert_eq!(&event.action, action);
            marks.push(mark(event, t_us / 1000, outcome));
        });
        let played = head.frame(&mut driver, frame);
        let servos = played.report.servos;
        rows.push(Row {
            frame,
            t_ms: t_us / 1000,
            angles: servos.map(|s| s.angle.millidegrees()),
            pulses: servos.map(|s| (u64::from(s.duty.0) * count_ps + 500) / 1000),
        });
    }
    interrupted(&mut marks, params.config().blend.0);
    for event in pending {
        println!(
            "line {}: at {} s, after the trace's end: not run",
            event.line,
            script::show_seconds(event.at_us)
        );
    }
    Ok(Trace { rows, marks })
}

/// A gesture interrupted by a newer one fades out within `blend_ms` of it:
/// its mark ends there.
fn interrupted(marks: &mut [Mark], blend_ms: u32) {
    let gestures: Vec<usize> = (0..marks.len())
        .filter(|&i| marks[i].reply.starts_with("ok ") && is_gesture(&marks[i]))
        .collect();
    for pair in gestures.windows(2) {
        let next = marks[pair[1]].t_ms;
        let mark = &mut marks[pair[0]];
        let end = next + u64::from(blend_ms);
        if mark.t_ms + mark.span_ms > end {
            mark.span_ms = end - mark.t_ms;
        }
    }
}

/// Whether the mark's reply is a gesture's (`ok <word> …`; every gesture of
/// the core's table).
fn is_gesture(mark: &Mark) -> bool {
    let word = mark.reply.split_whitespace().nth(1);
    GestureKind::ALL.iter().any(|k| word == Some(k.name()))
}

/// The mark of `event`, applied at `t_ms` with `outcome`.
fn mark(
    event: &Event,
    t_ms: u64,
    outcome: &Result<Applied, idle_head_core::behaviour::BehaviourError>,
) -> Mark {
    let word = event
        .text
        .split_whitespace()
        .next()
        .unwrap_or("")
        .to_owned();
    let (axes, span_ms, label, reply) = match outcome {
        Err(e) => (
            vec![],
            0,
            format!("{word} (refused)"),
            format!("err {} {e}", e.code()),
        ),
        Ok(Applied::Gesture(plan)) => (
            vec![plan.kind.axis()],
            u64::from(plan.duration.0),
            word,
            format!(
                "ok {} {} mdeg {} cycles {} ms intensity {}",
                plan.kind.name(),
                plan.amplitude.millidegrees(),
                plan.cycles,
                plan.duration.0,
                plan.intensity.get()
            ),
        ),
        Ok(Applied::Look(look)) => (
            vec![Axis::Pitch, Axis::Yaw],
            u64::from(look.duration.0),
            if look.clamped {
                "look (clamped)".to_owned()
            } else {
                word
            },
            format!(
                "ok look{} {} {} {} ms",
                if look.clamped { " clamped" } else { "" },
                look.pitch.millidegrees(),
                look.yaw.millidegrees(),
                look.duration.0
            ),
        ),
        Ok(Applied::Center(ms)) => (
            vec![Axis::Pitch, Axis::Yaw],
            u64::from(ms.0),
            word,
            format!("ok center {} ms", ms.0),
        ),
        Ok(Applied::Idle(p)) => (
            vec![],
            0,
            event.text.clone(),
            format!("ok idle {} %", p.get()),
        ),
        Ok(Applied::Stop) => (vec![], 0, word, "ok stop".to_owned()),
    };
    Mark {
        t_ms,
        span_ms,
        axes,
        label,
        reply,
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
    write_csv(&trace, &args.out)?;
    for mark in &trace.marks {
        println!("{:>9} ms  {}", mark.t_ms, mark.reply);
    }
    summary(&trace);
    println!("wrote {} ({} frames)", args.out.display(), trace.rows.len());
    if let Some(png) = &args.png {
        plot::draw(&trace, args.seed, png)?;
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
        // The first dip (frame 150 + 10) is the nod's 6°, over the idle
        // ducked by 60 %.
        let dip = frame(&nodding, 160)[0] - frame(&idle, 160)[0];
        let ducked = -frame(&idle, 160)[0] * 6 / 10;
        assert!(
            (dip - 6000 - ducked).abs() <= 3,
            "{dip}, ducked by {ducked}"
        );
    }
}
