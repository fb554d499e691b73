//! `cargo xtask trace`: the firmware's frames simulated on the host, as CSV
//! (and PNG): the core's frame engine, frame by frame as the frame task runs
//! it, fed by the script through the queue, the console's service and the
//! input task (`host.rs`).

mod host;
mod marks;
pub mod radar;
mod script;

use std::{fmt::Write as _, fs, path::Path, path::PathBuf};

use anyhow::{Context, Result, anyhow};
use idle_head_core::behaviour::{
    BehaviourConfig, BehaviourParams, CommandQueue, Head, LOOP_DURATION, ShowLink,
};
use idle_head_core::console::{ConsoleLink, HeadMode, HeadStatus};
use idle_head_core::driver::{DriverConfig, DriverParams, FrameDriver};
use idle_head_core::idle::{GenerateOnTake, IdlePlayer, IdleTiming, LoopSet, LoopStream};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N};
use idle_head_core::pwm_clock::{PICO_SYS_HZ, SliceClock};
use idle_head_core::servo::{ServoRate, SetPeriod};
use idle_head_core::settings::Settings;
use idle_head_core::{Axis, Microseconds, Playback, Timestamp};
use idle_head_firmware::config::IDLE_MODE;

pub use host::Watch;
use marks::Mark;
pub use script::{Event, Kind, parse as parse_script, show_seconds};

use crate::{project, steps::Steps};

/// Options of `cargo xtask trace`.
#[derive(Debug, Clone, PartialEq, Eq, clap::Args)]
pub struct Args {
    /// Simulated time in seconds (decimals allowed: 2.5).
    #[arg(long = "seconds", value_name = "s", value_parser = positive_seconds)]
    pub micros: u64,
    /// The idle loops the console's `seed n` gives a board; default: the
    /// Table 2 loops.
    #[arg(long, value_name = "n")]
    pub seed: Option<u32>,
    /// The commands and their times, one per line: `<seconds> <command>`.
    #[arg(long, value_name = "file")]
    pub script: Option<PathBuf>,
    /// The servos' rate (and the frame rate) from the first frame, Hz
    /// (50 to 333; a script's `servo rate` changes it later).
    #[arg(long, value_name = "hz", default_value = "50", value_parser = crate::args::servo_rate)]
    pub rate: ServoRate,
    /// The CSV to write [default: trace/trace.csv in the target directory].
    #[arg(long, value_name = "csv")]
    pub out: Option<PathBuf>,
    /// Also write the telemetry lines `watch` would stream meanwhile (the
    /// core's own, with the radar's people when a script turns it on), one
    /// a line, to this file.
    #[arg(long, value_name = "file")]
    pub telemetry: Option<PathBuf>,
    /// The telemetry's lines a second (1 to 50; the panel asks for 20).
    #[arg(long, value_name = "hz", default_value_t = 20, value_parser = clap::value_parser!(u8).range(1..=50))]
    pub watch: u8,
    /// Also draw the three axes over time, the commands marked, to this PNG
    /// [without a file: trace/trace.png in the target directory].
    #[arg(long, value_name = "file")]
    #[allow(clippy::option_option)] // absent, present without a value, with one
    pub png: Option<Option<PathBuf>>,
}

/// `--seconds`: more than 0, in µs.
fn positive_seconds(text: &str) -> Result<u64, String> {
    match script::seconds(text) {
        Ok(0) => Err("must be more than 0".to_owned()),
        Ok(us) => Ok(us),
        Err(e) => Err(e.to_string()),
    }
}

/// One frame of the trace (the frame's number is its index).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Row {
    pub t_us: u64,
    /// Commanded angles, m°; pulse widths, ns; the duties written, counts of
    /// the Pico's PWM (0: no pulse).
    pub angles: [i32; 3],
    pub pulses: [u64; 3],
    pub duties: [u16; 3],
}

/// The simulated run: its frames; the commands as applied and the looks'
/// returns, in time order; the telemetry lines, if asked for; the replies
/// to the lines asked of the console after the last frame.
pub struct Trace {
    pub rows: Vec<Row>,
    pub marks: Vec<Mark>,
    pub watch: Option<Watch>,
    pub answers: Vec<String>,
}

/// A PWM channel counted as the Pico's slice counts its period (the duty
/// written is the frame's report's, which the trace keeps).
#[derive(Clone, Copy)]
struct Channel(SliceClock);

impl Channel {
    fn at(period: Microseconds) -> Result<Self> {
        let clock = SliceClock::for_period(PICO_SYS_HZ, period)
            .map_err(|_| anyhow!("no Pico clock for {} µs", period.0))?;
        Ok(Self(clock))
    }
}

impl embedded_hal::pwm::ErrorType for Channel {
    type Error = embedded_hal::pwm::ErrorKind;
}

impl embedded_hal::pwm::SetDutyCycle for Channel {
    fn max_duty_cycle(&self) -> u16 {
        self.0.top
    }

    fn set_duty_cycle(&mut self, _: u16) -> Result<(), Self::Error> {
        Ok(())
    }
}

impl SetPeriod for Channel {
    fn set_period(&mut self, period: Microseconds) -> Result<(), Self::Error> {
        self.0 = SliceClock::for_period(PICO_SYS_HZ, period)
            .map_err(|_| embedded_hal::pwm::ErrorKind::Other)?;
        Ok(())
    }
}

/// The firmware's idle source: its stream of loop sets (never-repeating
/// unless built with `fixed-loop`), each generated when its join is due.
pub type Idle =
    IdlePlayer<Box<LoopSet<DEFAULT_N>>, GenerateOnTake<Box<LoopSet<DEFAULT_N>>, DEFAULT_N>>;

/// The idle of the `[pitch, roll, yaw]` seeds (else Table 2's loops).
pub fn idle(playback: Playback, seeds: Option<[u32; 3]>) -> Result<Idle> {
    let mut config = DEFAULT_HEAD;
    if let Some([pitch, roll, yaw]) = seeds {
        (config.pitch.seed, config.roll.seed, config.yaw.seed) = (pitch, roll, yaw);
    }
    let timing = IdleTiming::new(playback).map_err(|e| anyhow!("{}", e.message()))?;
    let mut stream = LoopStream::new(config, &timing);
    let mut first = Box::new(LoopSet::new());
    stream
        .next_into(&mut first)
        .map_err(|e| anyhow!("idle loops of seed {seeds:?}: {e}"))?;
    let supply = GenerateOnTake::new(stream, Box::new(LoopSet::new()));
    Ok(IdlePlayer::new(first, supply, timing, IDLE_MODE))
}

/// [`at_rate`] at 50 Hz: what the board runs.
pub fn built_in() -> Result<(DriverParams, BehaviourParams)> {
    at_rate(ServoRate::DEFAULT)
}

/// The built-in driver's parameters at `rate`, and the behaviour's built
/// on them; fails if a configuration is refused at that rate.
pub fn at_rate(rate: ServoRate) -> Result<(DriverParams, BehaviourParams)> {
    let mut config = DriverConfig::DEFAULT;
    (config.frame_period, config.pwm.period) = (rate.period(), rate.period());
    let driver = config.build().map_err(|e| anyhow!("{}", e.message()))?;
    let params = (BehaviourConfig::DEFAULT.build(&driver)).map_err(|e| anyhow!("{e}"))?;
    Ok((driver, params))
}

/// Runs `micros` of frames at `rate` with `events` (sorted by time), the
/// idle from `seed` (else Table 2's), a `watch` at `watch` lines a second,
/// and the console's replies to `ask` after the last frame.
pub fn simulate(
    micros: u64,
    seed: Option<[u32; 3]>,
    rate: ServoRate,
    events: &[Event],
    watch: Option<u8>,
    ask: &[&str],
) -> Result<Trace> {
    let mut watch = watch.map(Watch::new);
    let (driver_params, params) = at_rate(rate)?;
    let period = driver_params.config().frame_period;
    let playback =
        Playback::new(LOOP_DURATION, period, DEFAULT_N).map_err(|e| anyhow!("playback: {e:?}"))?;
    let mut head = Head::new(idle(playback, seed)?, params);
    let mut driver = FrameDriver::new([Channel::at(period)?; 3], driver_params);
    let (queue, link, show) = (CommandQueue::new(), ConsoleLink::new(), ShowLink::new());
    let mut beside = host::Beside::new(&queue, &link, &show, rate)?;
    let mut radar = radar::Radar::of(events);
    let refused = |t_us: u64| move |e| anyhow!("{} ms: servo rate refused: {e}", t_us / 1000);

    let mut rows = Vec::with_capacity(usize::try_from(micros / u64::from(period.0)).unwrap_or(0));
    let (mut marks, mut next, mut t_us) = (Vec::new(), 0, 0);
    while t_us < micros {
        let rest = head.rest_state();
        // The script's lines due, and the input task's wakes between them.
        while let Some(event) = events.get(next).filter(|e| e.at_us <= t_us) {
            beside.wake_until(event.at_us, rest);
            if !beside.take(event, rest) {
                break;
            }
            next += 1;
        }
        radar.send(&show, t_us);
        beside.radar = show.track.presence();
        beside.wake_until(t_us, rest);
        // What the console sent through the link: live settings,
        // calibrations, a new rate (the outputs from this frame on, the
        // frames after it); then the queue.
        if let Some(live) = link.take_live() {
            head.set_live(&mut driver, &live);
        }
        for (axis, cal) in Axis::ALL.iter().zip(link.take_servos()) {
            if let Some(Err(e)) = cal.map(|cal| head.set_servo(&mut driver, *axis, cal)) {
                let (ms, name) = (t_us / 1000, axis.name());
                println!("{ms} ms: {name} servo calibration refused: {e}");
            }
        }
        let retime = link.take_rate().map(ServoRate::period);
        if let Some(period) = retime {
            driver.set_pwm_period(period).map_err(refused(t_us))?;
        }
        let (ms, mut taken) = (t_us / 1000, std::mem::take(&mut beside.origins).into_iter());
        let mixer = *head.mixer().params();
        head.drain(&mut driver, &queue, |_, outcome| {
            if let Some((text, line)) = taken.next() {
                marks.extend(marks::marks(&text, line, ms, outcome, &mixer));
            }
        });
        beside.origins.extend(taken);
        let sighting = show.track.take();
        let settings = show.track.settings();
        head.track(&mut driver, Timestamp(t_us), &settings, sighting.as_ref());
        let report = head.frame(&mut driver, Timestamp(t_us)).report;
        if let Some(period) = retime {
            (head.set_frame_period(&mut driver, period)).map_err(refused(t_us))?;
        }
        // The status to the console's link, as the frame task publishes it
        // (the tracker's view while the radar is on), and to `watch`.
        let mode = HeadMode::of(driver.is_stopped(), driver.is_stopping(), head.rest_state());
        let mut status = HeadStatus::of(&report, driver.stats(), mode, Timestamp(t_us));
        status.idle = Some(head.idle_view());
        status.track = settings.radar.then(|| head.track_view());
        link.publish(status);
        if let Some(watch) = watch.as_mut() {
            watch.frame(t_us, &status);
        }
        let count_ps = driver.channels_mut()[0].0.count_ps(PICO_SYS_HZ);
        let servos = report.servos;
        rows.push(Row {
            t_us,
            angles: servos.map(|s| s.angle.millidegrees()),
            pulses: servos.map(|s| (u64::from(s.duty.0) * count_ps + 500) / 1000),
            duties: servos.map(|s| s.duty.0),
        });
        t_us += u64::from(driver.params().config().frame_period.0);
    }
    marks::settle(&mut marks, params.config().blend.0, t_us / 1000);
    for event in &events[next..] {
        let (number, at) = (event.line, show_seconds(event.at_us));
        println!("line {number}: at {at} s, after the trace's end: not run");
    }
    let answers = ask.iter().map(|line| beside.line(line).0).collect();
    Ok(Trace {
        rows,
        marks,
        watch,
        answers,
    })
}

/// `cargo xtask trace`: the CSV, and the PNG if asked for, to trace/ in the
/// target directory (build output, not the repository) unless told otherwise.
pub fn command(args: &Args) -> Result<bool> {
    let (_, params) = at_rate(args.rate)?;
    let events = (args.script.as_deref()).map(|path| read_script(path, &params));
    let events = events.transpose()?.unwrap_or_default();
    let seeds = args.seed.map(Settings::seeds_from);
    let watch = args.telemetry.as_ref().map(|_| args.watch);
    let trace = simulate(args.micros, seeds, args.rate, &events, watch, &[])?;
    let default = |name: &str| -> Result<PathBuf> {
        let target = project::metadata(&project::root())?.target_dir;
        Ok(target.join("trace").join(name))
    };
    let out = args.out.clone().map_or_else(|| default("trace.csv"), Ok)?;
    let mut csv = "frame,t_ms,pitch_mdeg,roll_mdeg,yaw_mdeg,pitch_ns,roll_ns,yaw_ns\n".to_owned();
    for (frame, row) in trace.rows.iter().enumerate() {
        let ([p, r, y], [pn, rn, yn]) = (row.angles, row.pulses);
        let _ = writeln!(csv, "{frame},{},{p},{r},{y},{pn},{rn},{yn}", ms(row.t_us));
    }
    project::write(&out, csv)?;
    for mark in &trace.marks {
        println!("{:>9} ms  {}", mark.t_ms, mark.reply);
    }
    // Range, largest step and largest change of step per axis.
    for axis in Axis::ALL {
        let i = axis.index();
        let angles: Vec<f64> = trace.rows.iter().map(|r| f64::from(r.angles[i])).collect();
        let (lo, hi) = (trace.rows.iter().map(|r| r.angles[i]))
            .fold((i32::MAX, i32::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let Steps { step, turn } = Steps::of(&angles);
        let (plo, phi) = (trace.rows.iter().map(|r| r.pulses[i]))
            .fold((u64::MAX, 0), |(lo, hi), p| (lo.min(p), hi.max(p)));
        println!(
            "{:<5} angle {lo}..{hi} mdeg, largest step {step:.0} mdeg/frame, largest change of step \
             {turn:.0} mdeg/frame² (frames as they came), pulses {plo}..{phi} ns",
            axis.name()
        );
    }
    println!("wrote {} ({} frames)", out.display(), trace.rows.len());
    if let (Some(path), Some(watch)) = (&args.telemetry, &trace.watch) {
        project::write(path, watch.lines.join("\n") + "\n")?;
        let (path, lines, hz) = (path.display(), watch.lines.len(), args.watch);
        println!("wrote {path} ({lines} telemetry lines, {hz} a second)");
    }
    if let Some(png) = &args.png {
        let png = png.clone().map_or_else(|| default("trace.png"), Ok)?;
        marks::draw(&trace, args.seed, &png)?;
        println!("wrote {}", png.display());
    }
    Ok(true)
}

pub fn read_script(path: &Path, params: &BehaviourParams) -> Result<Vec<Event>> {
    let text = fs::read_to_string(path)
        .with_context(|| format!("reading the script {}", path.display()))?;
    script::parse(&text, params).with_context(|| format!("{}", path.display()))
}

/// `t_us` in ms, with µs decimals where it has them (`2500`, `2498.496`).
pub fn ms(t_us: u64) -> String {
    match t_us % 1000 {
        0 => format!("{}", t_us / 1000),
        us => format!("{}.{us:03}", t_us / 1000),
    }
}

#[cfg(test)]
mod tests;
