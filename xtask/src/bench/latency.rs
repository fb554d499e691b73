//! The latency rows of `cargo xtask bench`: from an input to the servo pins,
//! in the RP2040 emulator on the shipped image (docs/dev/emulators.md). A
//! run per path, [`EVENTS`] or more at seeded random phases, each timed by
//! [`response`]; p50, p99 and max in ms, p99 against its goal.

use std::{fmt::Write as _, path::Path, time::Duration};

use anyhow::{Context, Result, bail, ensure};
use idle_head_core::servo::ServoRate;

use crate::figures;
use crate::project::Metadata;
use crate::sim::pulses::{self, Measured};
use crate::sim::script::{Against, Board, play};
use crate::sim::{Boot, node, parse_script, run_shipped, script_time};
use crate::trace::show_seconds;

/// Events per row, at least; more are scheduled, for the ones skipped.
pub const EVENTS: usize = 1000;
pub const SCHEDULED: usize = 1100;
/// The goal at 50 Hz (a frame and the transport), and at 200 Hz (5 ms frames).
pub const GOAL_MS: f64 = 25.0;
pub const GOAL_200_HZ_MS: f64 = 8.0;
/// The gaps between DMX events: a one-step move settles in a frame or two.
const DMX_GAP: (Duration, Duration) = (Duration::from_millis(80), Duration::from_millis(130));
/// The gaps between `look` events: a move starts a frame after the line and
/// takes two more.
pub const LOOK_GAP: (Duration, Duration) = (Duration::from_millis(110), Duration::from_millis(160));
/// The gaps between presses: a look of 100 ms and its start (up to 47 ms)
/// are over before the next; a press is held 30 ms.
const PRESS_GAP: (Duration, Duration) = (Duration::from_millis(150), Duration::from_millis(170));
const HELD: Duration = Duration::from_millis(30);
/// The input edge's run plays a script and computes its host trace: more
/// wall time than the others, at least.
const SCRIPT_WALL: Duration = Duration::from_secs(600);
/// The longest a port task may wait for the CPU, µs.
pub const PORT_WAIT_US: u32 = 1000;

/// Nearest-rank percentile `q` (0..=1) of sorted values.
#[allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]
fn percentile(sorted: &[f64], q: f64) -> f64 {
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len().max(1));
    sorted.get(rank - 1).copied().unwrap_or(f64::NAN)
}

/// One latency row: latencies (ms, sorted), events skipped (the axis still
/// moved), events per fifth of the frame, the three slowest (s, ms), the
/// port tasks' longest wait for the CPU (µs, as logged), the p99 goal (ms).
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub name: &'static str,
    pub ms: Vec<f64>,
    pub skipped: usize,
    pub phases: [usize; 5],
    pub worst: Vec<(f64, f64)>,
    pub waited_us: Option<u32>,
    pub goal_ms: f64,
}

impl Row {
    /// p50, p99 and the largest, ms.
    fn spread(&self) -> [f64; 3] {
        [0.5, 0.99, 1.0].map(|q| percentile(&self.ms, q))
    }

    fn met(&self) -> bool {
        self.spread()[1] <= self.goal_ms
    }

    /// The row for the measured figures: label, events, p50, p99, max, goal,
    /// the port tasks' longest wait.
    pub fn figure(&self) -> Vec<String> {
        let [p50, p99, max] = self.spread().map(|ms| format!("{ms:.1}"));
        let missed = if self.met() { "" } else { " (missed)" };
        let waited =
            (self.waited_us).map_or_else(|| "not logged".to_owned(), |us| format!("{us} µs"));
        let name = format!("latency {}", self.name);
        let n = figures::thousands(self.ms.len() as u64);
        let goal = format!("{:.0}{missed}", self.goal_ms);
        vec![name, n, p50, p99, max, goal, waited]
    }

    /// `latency <name> p50=… p99=… max=… events=… skipped=…`, and the spread.
    pub fn lines(&self) -> String {
        let [p50, p99, max] = self.spread();
        let (name, events, skipped) = (self.name, self.ms.len(), self.skipped);
        let mut text = format!(
            "latency {name} p50={p50:.1} p99={p99:.1} max={max:.1} events={events} skipped={skipped}\n"
        );
        let slowest: Vec<String> = (self.worst.iter())
            .map(|(at, ms)| format!("{ms:.1} ms at {at:.3} s"))
            .collect();
        let met = if self.met() { "met" } else { "missed" };
        let _ = writeln!(
            text,
            "  (ms; goal p99 ≤ {} ms: {met}; events per fifth of the frame: {:?}; slowest: {})",
            self.goal_ms,
            self.phases,
            slowest.join(", ")
        );
        if !self.met() {
            text += "  (where the time goes: the wait for the next frame (0 to a frame), the \
                     PWM's latch to the next period (a tenth of one), and the transport before \
                     the frame)\n";
        }
        if let Some(us) = self.waited_us {
            let _ = writeln!(text, "  (port tasks waited at most {us} µs for the CPU)");
        }
        text
    }

    /// The misses of the row's goals (p99 within its goal, the port tasks'
    /// wait within [`PORT_WAIT_US`]), if any.
    pub fn misses(&self) -> Option<String> {
        let (p99, mut misses) = (self.spread()[1], Vec::new());
        if !self.met() {
            misses.push(format!("p99 {p99:.1} ms over {} ms", self.goal_ms));
        }
        match self.waited_us {
            Some(us) if us > PORT_WAIT_US => {
                misses.push(format!(
                    "a port task waited {us} µs, over {PORT_WAIT_US} µs"
                ));
            }
            None => misses.push("the port tasks' wait was not logged".to_owned()),
            Some(_) => {}
        }
        (!misses.is_empty()).then(|| format!("latency {}: {}", self.name, misses.join(", ")))
    }
}

/// Fails unless `got` is `want`: `<got> <what>, not <want>`.
pub fn count(got: usize, want: usize, what: &str) -> Result<()> {
    ensure!(got == want, "{got} {what}, not {want}");
    Ok(())
}

/// Event times from `start`, each a random `gap` (from, to) after the last
/// (xorshift, seeded: the same every run).
pub fn schedule(
    start: Duration,
    count: usize,
    gap: (Duration, Duration),
    seed: u32,
) -> Vec<Duration> {
    let mut state = seed | 1;
    let span = u64::try_from(gap.1.saturating_sub(gap.0).as_micros())
        .unwrap_or(0)
        .max(1);
    let mut at = start;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        at += gap.0 + Duration::from_micros(u64::from(state) % span);
        at
    };
    (0..count).map(|_| next()).collect()
}

/// What became of one event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Response {
    /// The axis still moved (or had no pulse yet) when it came: skipped.
    Moving,
    /// No pulse after it reflects it.
    Never,
    /// The first pulse that reflects it rose this many ms after it.
    After(f64),
}

/// The response to an event at `at` (ns, once the input has fully arrived)
/// on an axis with `pulses`: the rise of the first pulse more than 1.5 PWM
/// counts off the baseline (the last two pulses before, of equal width).
pub fn response(pulses: &[Measured], at: f64, count_ns: f64) -> Response {
    let before = pulses.partition_point(|p| p.rise < at);
    let baseline = before.checked_sub(2).map(|i| (&pulses[i], &pulses[i + 1]));
    match baseline {
        Some((a, b)) if (a.width - b.width).abs() <= count_ns / 2.0 => pulses[before..]
            .iter()
            .find(|p| (p.width - b.width).abs() > count_ns * 1.5)
            .map_or(Response::Never, |p| Response::After((p.rise - at) / 1e6)),
        _ => Response::Moving,
    }
}

/// The row of `events` (ns) on yaw's pulses in `boot`, at 50 Hz.
pub fn row(name: &'static str, events: &[f64], boot: &Boot) -> Result<Row> {
    row_at(name, events, boot, ServoRate::DEFAULT, GOAL_MS)
}

/// [`row`] with the servos at `rate` (its frames, and its PWM count for the
/// response), against the p99 goal `goal_ms`.
pub fn row_at(
    name: &'static str,
    events: &[f64],
    boot: &Boot,
    rate: ServoRate,
    goal_ms: f64,
) -> Result<Row> {
    let pulses = &pulses::measure(&boot.trains[2]);
    let count_ns = crate::sim::run::timing_at(rate).count_ns;
    let frame_ns = f64::from(rate.period().0) * 1e3;
    let (mut ms, mut worst, mut skipped, mut phases) = (Vec::new(), Vec::new(), 0, [0; 5]);
    let first = pulses.first().map_or(0.0, |p| p.rise);
    for &at in events {
        match response(pulses, at, count_ns) {
            Response::Moving => skipped += 1,
            Response::Never => bail!("{name}: no pulse reflects the event at {:.3} s", at / 1e9),
            Response::After(latency) => {
                ms.push(latency);
                worst.push((at / 1e9, latency));
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
                let fifth = (((at - first).rem_euclid(frame_ns)) / (frame_ns / 5.0)) as usize;
                phases[fifth.min(4)] += 1;
            }
        }
    }
    ensure!(
        ms.len() >= EVENTS,
        "{name}: {} events measured ({skipped} skipped), fewer than {EVENTS}",
        ms.len()
    );
    ms.sort_by(f64::total_cmp);
    worst.sort_by(|a, b| b.1.total_cmp(&a.1));
    worst.truncate(3);
    // The last `port tasks waited at most <n> us` the image logged (it logs
    // each longer wait within a second).
    let waited_us = boot.log.iter().rev().find_map(|(_, line)| {
        let rest = line.message.strip_prefix("port tasks waited at most ")?;
        rest.strip_suffix(" us")?.parse().ok()
    });
    Ok(Row {
        name,
        ms,
        skipped,
        phases,
        worst,
        waited_us,
        goal_ms,
    })
}

/// Where and how long the shipped image runs: the project, the wall time.
pub type Shipped<'a> = (&'a Path, &'a Metadata, Duration);

/// The first boot of the shipped image, set up by `setup`, run until 0.5 s
/// after the last of the events at `times`.
pub fn first_boot(
    (root, metadata, wall): Shipped,
    times: &[Duration],
    setup: impl FnOnce(&mut node::Config),
) -> Result<Boot> {
    let end = times.last().copied().unwrap_or_default() + Duration::from_millis(500);
    let report = run_shipped(root, metadata, end, wall, setup)?;
    report.boots.into_iter().next().context("no boot")
}

/// `latency dmx`: a console at full mix moves yaw one coarse step up and
/// down; each change's DMX frame against yaw's first pulse that moves.
pub fn dmx(root: &Path, metadata: &Metadata, wall: Duration) -> Result<Row> {
    let start = Duration::from_secs(4);
    let times = schedule(start, SCHEDULED, DMX_GAP, 0x5eed_d3c5);
    let mut script = String::from("2.5 7=255 1=100 3=128 5=128 9=255\n");
    for (k, at) in times.iter().enumerate() {
        // 101, 100, 101, …: every event a change from the set-up's 100.
        let _ = writeln!(script, "{:.6} 1={}", at.as_secs_f64(), 101 - k % 2);
    }
    let line = crate::sim::dmx::line(&crate::sim::dmx::parse(&script)?);
    let run = (root, metadata, wall);
    let boot = &first_boot(run, &times, |config| config.dmx = Some(line))?;
    // The first change is the set-up's.
    let events: Vec<f64> = boot.dmx_changes.iter().skip(1).copied().collect();
    count(events.len(), times.len(), "DMX frames carried a change")?;
    row("dmx", &events, boot)
}

/// `latency input edge`: the idle off, GP2 and GP3 buttons each with a
/// short look, pressed in turn; each edge against yaw's first pulse that
/// moves. Every pulse is checked too ([`Against::Written`]).
pub fn input_edge(root: &Path, metadata: &Metadata, wall: Duration) -> Result<Row> {
    let times = schedule(Duration::from_secs(2), SCHEDULED, PRESS_GAP, 0x2545_f491);
    let events = parse_script(&press_script(&times))?;
    let time = script_time(&events);
    let (limits, board) = ((time, wall.max(SCRIPT_WALL)), Board::default());
    let report = play(root, metadata, events, limits, Against::Written, board)?;
    if !report.problems.is_empty() {
        let problems = report.problems.join("\n  ");
        bail!("the input edge's run failed its checks:\n  {problems}");
    }
    let boot = report.first()?;
    let edges: Vec<f64> = boot.drives.iter().filter(|d| !d.2).map(|d| d.0).collect();
    count(edges.len(), times.len(), "presses went out")?;
    row("input edge", &edges, boot)
}

/// The input edge's script: the idle off (it fades out in a second, before
/// the first press), two look buttons, a press at each of `times` (from the
/// first frame), GP2 and GP3 in turn.
fn press_script(times: &[Duration]) -> String {
    let mut text = String::from(
        "0 idle off\n0 input 2 button look 0 2000 100 hold=stay\n0 input 3 button look 0 0 100 hold=stay\n",
    );
    let show = |at: Duration| show_seconds(u64::try_from(at.as_micros()).unwrap_or(u64::MAX));
    for (k, &at) in times.iter().enumerate() {
        let (pin, press, release) = (2 + k % 2, show(at), show(at + HELD));
        let _ = writeln!(text, "{press} pin {pin} low\n{release} pin {pin} high");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_pulse_that_moves_after_a_settled_axis() {
        let count = 312.5;
        let pulse = |k: usize, width_us: f64| Measured {
            rise: (10.0 + 20.0 * k as f64) * 1e6,
            width: width_us * 1e3,
        };
        let widths = [1500.0, 1500.0, 1500.0, 1500.3125, 1502.0, 1503.0];
        let pulses: Vec<Measured> = (0..6).map(|k| pulse(k, widths[k])).collect();
        // An event at 55 ms: a count of change is noise, 1502 µs moves.
        assert_eq!(response(&pulses, 55e6, count), Response::After(35.0));
        // The axis still moved before 95 ms; nothing before 5 ms: no baseline.
        assert_eq!(response(&pulses, 95e6, count), Response::Moving);
        assert_eq!(response(&pulses, 5e6, count), Response::Moving);
        let still = vec![pulse(0, 1500.0); 4];
        assert_eq!(response(&still, 30e6, count), Response::Never);
    }

    #[test]
    fn percentiles_goals_and_schedules() {
        let row = |ms: Vec<f64>, waited_us, goal_ms| Row {
            name: "x",
            ms,
            skipped: 0,
            phases: [0; 5],
            worst: Vec::new(),
            waited_us,
            goal_ms,
        };
        let values: Vec<f64> = (1..=100).map(f64::from).collect();
        let ranks = [0.0, 0.5, 0.99, 1.0].map(|q| percentile(&values, q));
        assert_eq!(ranks[..], [1.0, 50.0, 99.0, 100.0]);
        assert!(percentile(&[], 0.5).is_nan());
        let slow = row((1..=200).map(f64::from).collect(), Some(300), GOAL_MS);
        assert_eq!(slow.spread()[..2], [100.0, 198.0]);
        let lines = slow.lines();
        assert!(lines.starts_with("latency x p50=100.0 p99=198.0 max=200.0 events=200"));
        assert!(lines.contains("where the time goes"));
        assert_eq!(slow.misses().unwrap(), "latency x: p99 198.0 ms over 25 ms");
        let fast = row(vec![10.0; 100], Some(300), GOAL_MS);
        assert_eq!(fast.misses(), None);
        assert!(!fast.lines().contains("where the time goes"));
        let slow_port = "a port task waited 1001 µs, over 1000 µs";
        for (ms, waited, goal, miss) in [
            (10.0, Some(1001), GOAL_MS, slow_port),
            (10.0, None, GOAL_MS, "the port tasks' wait was not logged"),
            (8.5, Some(300), GOAL_200_HZ_MS, "p99 8.5 ms over 8 ms"),
        ] {
            let misses = row(vec![ms; 100], waited, goal).misses();
            assert_eq!(misses.unwrap(), format!("latency x: {miss}"));
        }
        let times = schedule(Duration::from_secs(1), 100, DMX_GAP, 7);
        assert_eq!(times, schedule(Duration::from_secs(1), 100, DMX_GAP, 7));
        let mut gaps = times.windows(2).map(|w| w[1].saturating_sub(w[0]));
        assert!(gaps.all(|gap| (DMX_GAP.0..DMX_GAP.1).contains(&gap)));
    }
}
