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

use idle_head_core::pwm_clock::{PICO_SERVO_CLOCK, PICO_SYS_HZ};
use marks::Mark;
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
            marks.extend(marks::marks(event, t_us / 1000, outcome, &params));
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
    marks::settle(
        &mut marks,
        params.config().blend.0,
        frames * frame_us / 1000,
    );
    for event in pending {
        println!(
            "line {}: at {} s, after the trace's end: not run",
            event.line,
            script::show_seconds(event.at_us)
        );
    }
    Ok(Trace { rows, marks })
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
