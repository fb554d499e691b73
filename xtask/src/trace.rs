//! `cargo xtask trace`: the firmware's frames simulated on the host, as CSV
//! (and PNG). The core's frame engine runs frame by frame as the frame task
//! does, with the built-in configuration at 50 Hz or `--rate` (a script's
//! `servo rate` changes it between two frames, as on the board); a
//! script's motion lines go through the same queue, its console lines
//! through the console's service, its pin lines into the input task
//! (`host.rs`). A row per frame:
//! `frame,t_ms,pitch_mdeg,roll_mdeg,yaw_mdeg,pitch_ns,roll_ns,yaw_ns`
//! (`t_ms` with µs decimals where it has them).

mod host;
mod marks;
pub mod radar;
mod script;
mod watch;

use std::{fs, path::PathBuf};

use anyhow::{Context, Result, anyhow};
use idle_head_core::behaviour::{BehaviourConfig, CommandQueue, Head, LOOP_DURATION, ShowLink};
use idle_head_core::driver::{DriverConfig, DriverParams, FrameDriver, FrameReport};
use idle_head_core::idle::{GenerateOnTake, IdlePlayer, IdleTiming, LoopSet, LoopStream};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadConfig, Lcg};
use idle_head_core::pwm_clock::SliceClock;
use idle_head_core::servo::{ServoRate, SetPeriod};
use idle_head_core::{Axis, Microseconds, Playback, Timestamp};
use idle_head_firmware::config::IDLE_MODE;
use std::fmt::Write as _;

use host::Origin;
use idle_head_core::behaviour::BehaviourParams;
use idle_head_core::console::{ConsoleLink, HeadMode, HeadStatus};
use idle_head_core::pwm_clock::PICO_SYS_HZ;
use marks::Mark;
pub use script::{Event, Kind};
pub use watch::Watch;

use crate::{project, steps::Steps};

/// A script's events (see `script.rs`), checked with `params`.
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
    /// The servos' rate (and the frame rate) from the first frame, Hz
    /// (50 to 333; a script's `servo rate` changes it later).
    #[arg(long, value_name = "hz", default_value_t = 50,
          value_parser = clap::value_parser!(u16).range(50..=333))]
    pub rate: u16,
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

/// One frame of the trace.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Row {
    pub frame: u64,
    /// Time of the frame in ms (rounded down).
    pub t_ms: u64,
    /// Time of the frame in µs.
    pub t_us: u64,
    /// Commanded angles, m°.
    pub angles: [i32; 3],
    pub pulses: [u64; 3],
    /// The duties written, counts of the Pico's PWM (0: no pulse).
    pub duties: [u16; 3],
    /// The frame period after this frame, µs.
    pub period_us: u32,
}

/// The simulated run.
pub struct Trace {
    pub rows: Vec<Row>,
    /// The script's commands as applied, and the looks' returns, in time
    /// order.
    pub marks: Vec<Mark>,
    /// The telemetry lines, when asked for ([`simulate_watched`]).
    pub watch: Option<Watch>,
    /// The replies to the lines asked of the console after the last frame
    /// ([`simulate_watched`]).
    pub answers: Vec<String>,
}

/// A PWM channel that keeps the last duty, counted as the Pico's slice
/// counts its period.
struct Channel {
    duty: u16,
    clock: SliceClock,
}

impl Channel {
    fn at(period: Microseconds) -> Result<Self> {
        let clock = SliceClock::for_period(PICO_SYS_HZ, period)
            .map_err(|_| anyhow!("no Pico clock for {} µs", period.0))?;
        Ok(Self { duty: 0, clock })
    }
}

impl embedded_hal::pwm::ErrorType for Channel {
    type Error = embedded_hal::pwm::ErrorKind;
}

impl embedded_hal::pwm::SetDutyCycle for Channel {
    fn max_duty_cycle(&self) -> u16 {
        self.clock.top
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        self.duty = duty;
        Ok(())
    }
}

impl SetPeriod for Channel {
    fn set_period(&mut self, period: Microseconds) -> Result<(), Self::Error> {
        self.clock = SliceClock::for_period(PICO_SYS_HZ, period)
            .map_err(|_| embedded_hal::pwm::ErrorKind::Other)?;
        Ok(())
    }
}

/// `--seed n`: pitch n, roll and yaw the next two values of the paper's
/// LCG.
fn lcg_seeds(seed: u32) -> [u32; 3] {
    let mut lcg = Lcg::new(seed);
    [seed, lcg.next_value(), lcg.next_value()]
}

/// The idle loops' configuration for `seeds` `[pitch, roll, yaw]` (or
/// Table 2's).
fn config(seeds: Option<[u32; 3]>) -> HeadConfig {
    let mut config = DEFAULT_HEAD;
    if let Some([pitch, roll, yaw]) = seeds {
        config.pitch.seed = pitch;
        config.roll.seed = roll;
        config.yaw.seed = yaw;
    }
    config
}

/// The firmware's idle source for `config`: its stream of loop sets
/// (never-repeating unless built with `fixed-loop`), each generated when
/// its join is due.
pub type Idle =
    IdlePlayer<Box<LoopSet<DEFAULT_N>>, GenerateOnTake<Box<LoopSet<DEFAULT_N>>, DEFAULT_N>>;

pub fn idle(config: HeadConfig, playback: Playback, seed: Option<[u32; 3]>) -> Result<Idle> {
    let timing = IdleTiming::new(playback).map_err(|e| anyhow!("{}", e.message()))?;
    let mut stream = LoopStream::new(config, &timing);
    let mut first = Box::new(LoopSet::new());
    stream
        .next_into(&mut first)
        .map_err(|e| anyhow!("idle loops of seed {seed:?}: {e}"))?;
    let supply = GenerateOnTake::new(stream, Box::new(LoopSet::new()));
    Ok(IdlePlayer::new(first, supply, timing, IDLE_MODE))
}

/// The built-in driver's parameters and the behaviour's built on them:
/// what the board runs.
pub fn built_in() -> Result<(DriverParams, BehaviourParams)> {
    at_rate(ServoRate::DEFAULT)
}

/// The built-in driver's parameters at `rate`, and the behaviour's built
/// on them.
///
/// # Errors
/// If a configuration is refused at that rate.
pub fn at_rate(rate: ServoRate) -> Result<(DriverParams, BehaviourParams)> {
    let mut config = DriverConfig::DEFAULT;
    config.frame_period = rate.period();
    config.pwm.period = rate.period();
    let driver = config.build().map_err(|e| anyhow!("{}", e.message()))?;
    let params = BehaviourConfig::DEFAULT
        .build(&driver)
        .map_err(|e| anyhow!("{e}"))?;
    Ok((driver, params))
}

/// Runs `micros` of frames at `rate` with `events` (sorted by time):
/// motion lines through the queue, other console lines through the
/// console's service, pin lines into the input task ([`host`]), radar
/// lines as the radar's frames ([`radar`]); the idle from `seed` (`[pitch,
/// roll, yaw]`, else Table 2's).
pub fn simulate(
    micros: u64,
    seed: Option<[u32; 3]>,
    rate: ServoRate,
    events: &[Event],
) -> Result<Trace> {
    simulate_watched(micros, seed, rate, events, None, &[])
}

/// As [`simulate`], with the telemetry lines of a `watch` (if `watch`
/// gives its lines a second), and the console's replies to `ask` after the
/// last frame.
pub fn simulate_watched(
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
    let idle = idle(config(seed), playback, seed)?;
    let mut head = Head::new(idle, params);
    let channels = [
        Channel::at(period)?,
        Channel::at(period)?,
        Channel::at(period)?,
    ];
    let mut driver = FrameDriver::new(channels, driver_params);
    let queue: CommandQueue = CommandQueue::new();
    let link = ConsoleLink::new();
    let show = ShowLink::new();
    let mut console = host::Console::new(&queue, &link, &show, rate)?;
    let mut task = host::Task::new(&link);
    // What the radar sees (a script's radar lines), sent at its 10 Hz.
    let mut radar = radar::Radar::of(events);

    let mut rows = Vec::with_capacity(usize::try_from(micros / u64::from(period.0)).unwrap_or(0));
    let mut marks = Vec::new();
    let mut next = 0;
    // Where each queued action came from, oldest first.
    let mut origins: Vec<Origin> = Vec::new();
    let (mut frame, mut t_us) = (0, 0);
    while t_us < micros {
        let rest = head.rest_state();
        // The script's lines due, and the input task's wakes between them.
        while let Some(event) = events.get(next).filter(|e| e.at_us <= t_us) {
            if let Kind::Radar(_) = event.kind {
                next += 1;
                continue;
            }
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
        radar.send(&show, t_us);
        task.radar(show.track.presence());
        wake_until(&mut task, t_us, rest, &link, &queue, &mut origins);
        // What the console sent through the link, then the queue.
        from_link(&link, &mut head, &mut driver, t_us);
        // A new rate: the outputs from this frame on, the frames after it.
        let retime = link.take_rate().map(ServoRate::period);
        if let Some(period) = retime {
            driver
                .set_pwm_period(period)
                .map_err(|e| anyhow!("{} ms: servo rate refused: {e}", t_us / 1000))?;
        }
        drain(
            &mut head,
            &mut driver,
            &queue,
            &mut origins,
            events,
            t_us,
            &mut marks,
        );
        let sighting = show.track.take();
        head.track(
            &mut driver,
            Timestamp(t_us),
            &show.track.settings(),
            sighting.as_ref(),
        );
        let played = head.frame(&mut driver, Timestamp(t_us));
        if let Some(period) = retime {
            head.set_frame_period(&mut driver, period)
                .map_err(|e| anyhow!("{} ms: servo rate refused: {e}", t_us / 1000))?;
        }
        let report = played.report;
        publish(
            &head,
            &driver,
            &report,
            (&link, &show),
            t_us,
            watch.as_mut(),
        );
        let period_us = driver.params().config().frame_period.0;
        rows.push(row(frame, t_us, &report, &mut driver));
        frame += 1;
        t_us += u64::from(period_us);
    }
    marks::settle(&mut marks, params.config().blend.0, t_us / 1000);
    events[next..].iter().for_each(script::not_run);
    let answers = ask.iter().map(|line| console.line(line).0).collect();
    Ok(Trace {
        rows,
        marks,
        watch,
        answers,
    })
}

/// Publishes the status after the frame at `t_us` that wrote `report` to
/// the console's link, as the frame task does (the tracker's view while
/// the radar is on), and to `watch`, if one streams.
fn publish(
    head: &Head<Idle>,
    driver: &FrameDriver<Channel>,
    report: &FrameReport,
    (link, show): (&ConsoleLink, &ShowLink),
    t_us: u64,
    watch: Option<&mut Watch>,
) {
    let mode = HeadMode::of(driver.is_stopped(), driver.is_stopping(), head.rest_state());
    let mut status = HeadStatus::of(report, driver.stats(), mode, Timestamp(t_us));
    status.idle = Some(head.idle_view());
    if show.track.settings().radar {
        status.track = Some(head.track_view());
    }
    link.publish(status);
    if let Some(watch) = watch {
        watch.frame(t_us, &status);
    }
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
            // Taken by the frame loop.
            Kind::Radar(_) => {}
        }
        true
    }
}

/// The row of frame `frame` at `t_us` that wrote `report`.
fn row(frame: u64, t_us: u64, report: &FrameReport, driver: &mut FrameDriver<Channel>) -> Row {
    let servos = report.servos;
    let count_ps = driver.channels_mut()[0].clock.count_ps(PICO_SYS_HZ);
    Row {
        frame,
        t_ms: t_us / 1000,
        t_us,
        angles: servos.map(|s| s.angle.millidegrees()),
        pulses: servos.map(|s| (u64::from(s.duty.0) * count_ps + 500) / 1000),
        duties: servos.map(|s| s.duty.0),
        period_us: driver.params().config().frame_period.0,
    }
}

/// The queue's actions taken before the frame at `t_us`, each marked with
/// the line (or other source) it came from.
fn drain(
    head: &mut Head<Idle>,
    driver: &mut FrameDriver<Channel>,
    queue: &CommandQueue,
    origins: &mut Vec<Origin>,
    events: &[Event],
    t_us: u64,
    marks: &mut Vec<Mark>,
) {
    let params = *head.mixer().params();
    let mut taken = origins.drain(..).collect::<std::collections::VecDeque<_>>();
    head.drain(driver, queue, |action, outcome| {
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
}

/// Between frames: the live settings and calibrations the console sent
/// (the rate is the frame's, [`simulate`]).
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

/// `cargo xtask trace`: the CSV, and the PNG if asked for, to trace/ in the
/// target directory (build output, not the repository) unless told otherwise.
pub fn command(args: &Args) -> Result<bool> {
    let rate = ServoRate::new(args.rate).context("not a servo rate")?;
    let (_, params) = at_rate(rate)?;
    let events = match &args.script {
        Some(path) => {
            let text = fs::read_to_string(path)
                .with_context(|| format!("reading the script {}", path.display()))?;
            script::parse(&text, &params).with_context(|| format!("{}", path.display()))?
        }
        None => Vec::new(),
    };
    let watch = args.telemetry.as_ref().map(|_| args.watch);
    let trace = simulate_watched(
        args.micros,
        args.seed.map(lcg_seeds),
        rate,
        &events,
        watch,
        &[],
    )?;
    let dir = || -> Result<PathBuf> {
        Ok(project::metadata(&project::root())?
            .target_dir
            .join("trace"))
    };
    let out = args
        .out
        .clone()
        .map_or_else(|| Ok(dir()?.join("trace.csv")), Ok::<_, anyhow::Error>)?;
    let mut csv =
        String::from("frame,t_ms,pitch_mdeg,roll_mdeg,yaw_mdeg,pitch_ns,roll_ns,yaw_ns\n");
    for row in &trace.rows {
        let ([p, r, y], [pn, rn, yn]) = (row.angles, row.pulses);
        let _ = writeln!(
            csv,
            "{},{},{p},{r},{y},{pn},{rn},{yn}",
            row.frame,
            ms(row.t_us)
        );
    }
    project::write(&out, csv)?;
    for mark in &trace.marks {
        println!("{:>9} ms  {}", mark.t_ms, mark.reply);
    }
    // Range, largest step and largest change of step per axis.
    for axis in Axis::ALL {
        let i = axis.index();
        let (lo, hi) = (trace.rows.iter().map(|r| r.angles[i]))
            .fold((i32::MAX, i32::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let angles: Vec<f64> = trace.rows.iter().map(|r| f64::from(r.angles[i])).collect();
        let Steps { step, turn } = Steps::of(&angles);
        let pulses = trace.rows.iter().map(|r| r.pulses[i]);
        let (plo, phi) = pulses.fold((u64::MAX, 0), |(lo, hi), p| (lo.min(p), hi.max(p)));
        println!(
            "{:<5} angle {lo}..{hi} mdeg, largest step {step:.0} mdeg/frame, largest change of step \
             {turn:.0} mdeg/frame² (frames as they came), pulses {plo}..{phi} ns",
            axis.name()
        );
    }
    println!("wrote {} ({} frames)", out.display(), trace.rows.len());
    if let (Some(path), Some(watch)) = (&args.telemetry, &trace.watch) {
        project::write(path, watch.lines.join("\n") + "\n")?;
        println!(
            "wrote {} ({} telemetry lines, {} a second)",
            path.display(),
            watch.lines.len(),
            args.watch
        );
    }
    if let Some(png) = &args.png {
        let png = png
            .clone()
            .map_or_else(|| Ok(dir()?.join("trace.png")), Ok::<_, anyhow::Error>)?;
        marks::draw(&trace, args.seed, &png)?;
        println!("wrote {}", png.display());
    }
    Ok(true)
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
