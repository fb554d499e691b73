//! The latency rows of `cargo xtask bench`: how long an input takes to
//! reach the servo pins, measured in the RP2040 emulator on the shipped
//! image.
//!
//! # Method
//!
//! One emulator run per path, with at least [`EVENTS`] events. The events
//! come at random times (a seeded generator: every run is the same), each a
//! random gap after the last, a little longer than the head takes to
//! settle after one and spread over several frames, so their phases against
//! the 20 ms frame are spread evenly (the rows print the events in each
//! fifth of the frame). For each event:
//!
//! - its time: when the input has fully arrived (the path's own: the end of
//!   the DMX frame that carries the change, the moment the USB host hands
//!   over the line's last byte, the harness driving a button's pin low);
//! - the baseline: the axis at rest before it, the last two pulses before
//!   the event of equal width (an event whose axis still moves is skipped
//!   and counted);
//! - the response: the rising edge of the first pulse after the event whose
//!   width differs from the baseline by more than one and a half counts
//!   of the PWM at the row's rate (0.47 µs at 50 Hz, 0.12 µs at 200 Hz):
//!   the first pulse that reflects the input.
//!
//! The latency is the response's time minus the event's; the row gives the
//! median, the 99th percentile and the largest, in ms:
//!
//! ```text
//! latency dmx p50=<ms> p99=<ms> max=<ms> events=<n> skipped=<n>
//! ```
//!
//! The goal is p99 within 25 ms (a frame and the transport); the rows
//! report against it without failing. A path's runs live in a function of
//! their own below ([`dmx`], [`usb_look`], [`input_edge`]); another path
//! adds one the same way, with its own events and axis.
//!
//! # An input edge
//!
//! The `input edge` row plays a script (`sim --script`'s): the idle off (so
//! that a pulse moves only because of a press), two buttons, GP2 and GP3,
//! each with a short look (`look 0 2000 100 hold=stay`, and back to 0),
//! pressed in turn 150 to 170 ms apart and released 30 ms later. Every
//! pulse of the run is checked as well (`sim::script`): each carries its
//! own frame's duty, on time, within the servos' limits; and every press
//! must move the head.
//!
//! # Where the time goes
//!
//! Every path: the wait for the next frame, which takes the input (0 to a
//! frame, 20 ms at 50 Hz), and the PWM's latch, which puts a frame's duty
//! out at the next period, a tenth of a period (2 ms) after the frame is
//! written. What comes before the frame is the transport's: microseconds
//! for USB and a button's edge (a leading-edge debounce), up to a
//! millisecond for UART0 (the ring the DMA fills is looked at every
//! millisecond). The rows also give the longest a port task waited for the
//! CPU in the run, as the image measures it.

use std::{fmt::Write as _, path::Path, time::Duration};

use anyhow::{Context, Result, bail};
use idle_head_core::servo::ServoRate;

use crate::project::Metadata;
use crate::sim::pulses::{self, Measured};
use crate::sim::{Boot, dmx_line, parse_script, play_script, run_shipped, script_time};

pub use super::paths::PATHS;

/// Events per row, at least.
pub const EVENTS: usize = 1000;
/// More are scheduled, for the ones skipped.
pub const SCHEDULED: usize = 1100;
/// The goal at 50 Hz: a frame and the transport.
pub const GOAL_MS: f64 = 25.0;
/// The goal at 200 Hz (5 ms frames).
pub const GOAL_200_HZ_MS: f64 = 8.0;
/// The gaps between DMX events: a one-step move settles in a frame or two.
const DMX_GAP: (Duration, Duration) = (Duration::from_millis(80), Duration::from_millis(130));
/// The gaps between `look` events: a move starts a frame after the line and
/// takes two more.
pub const LOOK_GAP: (Duration, Duration) = (Duration::from_millis(110), Duration::from_millis(160));
/// The gaps between presses: a look of 100 ms and its start (up to 47 ms)
/// are over before the next.
const PRESS_GAP: (Duration, Duration) = (Duration::from_millis(150), Duration::from_millis(170));
/// How long a button is held.
const HELD: Duration = Duration::from_millis(30);
/// The input edge's run plays a script, and computes its host trace: more
/// wall time than the others, at least.
const SCRIPT_WALL: Duration = Duration::from_secs(600);
/// Where a row's time goes (see the [module docs](self)).
const TIME_GOES: &str = "the wait for the next frame (0 to a frame), the PWM's latch to the \
     next period (a tenth of one), and the transport before the frame";
/// The longest a port task may wait for the CPU, µs.
pub const PORT_WAIT_US: u32 = 1000;

/// One latency row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// `dmx`, `usb look`, `input edge`.
    pub name: &'static str,
    /// Latencies, ms, sorted.
    pub ms: Vec<f64>,
    /// Events skipped: the axis still moved when they came.
    pub skipped: usize,
    /// Events' phases against the frame, per fifth of it.
    pub phases: [usize; 5],
    /// The three slowest events: when (s) and their latency (ms).
    pub worst: Vec<(f64, f64)>,
    /// The longest a port task waited for the CPU in the run, µs, as the
    /// image logged it.
    pub waited_us: Option<u32>,
    /// The row's goal for p99, ms.
    pub goal_ms: f64,
}

impl Row {
    /// The row for the measured figures: label, events, p50, p99, max, goal,
    /// the port tasks' longest wait.
    pub fn figure(&self) -> Vec<String> {
        let (p99, ms) = (self.percentile(99.0), |v: f64| format!("{v:.1}"));
        let missed = if p99 <= self.goal_ms { "" } else { " (missed)" };
        vec![
            format!("latency {}", self.name),
            crate::figures::thousands(self.ms.len() as u64),
            ms(self.percentile(50.0)),
            ms(p99),
            ms(self.ms.last().copied().unwrap_or(f64::NAN)),
            format!("{:.0}{missed}", self.goal_ms),
            self.waited_us
                .map_or_else(|| "not logged".to_owned(), |us| format!("{us} µs")),
        ]
    }

    /// The `p`-th percentile (nearest rank), ms.
    pub fn percentile(&self, p: f64) -> f64 {
        if self.ms.is_empty() {
            return f64::NAN;
        }
        #[allow(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            clippy::cast_precision_loss
        )]
        let rank = ((p / 100.0 * self.ms.len() as f64).ceil() as usize).clamp(1, self.ms.len());
        self.ms[rank - 1]
    }

    /// `latency <name> p50=… p99=… max=… events=… skipped=…`, and the spread.
    pub fn lines(&self) -> String {
        let mut text = format!(
            "latency {} p50={:.1} p99={:.1} max={:.1} events={} skipped={}\n",
            self.name,
            self.percentile(50.0),
            self.percentile(99.0),
            self.ms.last().copied().unwrap_or(f64::NAN),
            self.ms.len(),
            self.skipped
        );
        let _ = writeln!(
            text,
            "  (ms; goal p99 ≤ {} ms: {}; events per fifth of the frame: {:?}; slowest: {})",
            self.goal_ms,
            if self.percentile(99.0) <= self.goal_ms {
                "met"
            } else {
                "missed"
            },
            self.phases,
            self.worst
                .iter()
                .map(|(at, ms)| format!("{ms:.1} ms at {at:.3} s"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        if self.percentile(99.0) > self.goal_ms {
            let _ = writeln!(text, "  (where the time goes: {TIME_GOES})");
        }
        if let Some(us) = self.waited_us {
            let _ = writeln!(text, "  (port tasks waited at most {us} µs for the CPU)");
        }
        text
    }

    /// Whether the row meets its goals: p99 within its goal, the port
    /// tasks' wait within [`PORT_WAIT_US`]; the misses if not.
    pub fn misses(&self) -> Option<String> {
        let p99 = self.percentile(99.0);
        let mut misses = Vec::new();
        if p99.is_nan() || p99 > self.goal_ms {
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

/// Event times from `start`, each a random `gap` (from, to) after the last
/// (xorshift, seeded: the same every run).
pub fn schedule(
    start: Duration,
    count: usize,
    gap: (Duration, Duration),
    seed: u32,
) -> Vec<Duration> {
    let mut state = seed | 1;
    let mut at = start;
    let span = u64::try_from(gap.1.saturating_sub(gap.0).as_micros()).unwrap_or(0);
    (0..count)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            at += gap.0 + Duration::from_micros(u64::from(state) % span.max(1));
            at
        })
        .collect()
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

/// The response to an event at `at` (ns) on an axis whose pulses are
/// `pulses`.
pub fn response(pulses: &[Measured], at: f64, count_ns: f64) -> Response {
    let before = pulses.partition_point(|p| p.rise < at);
    let (Some(a), Some(b)) = (
        before.checked_sub(2).and_then(|i| pulses.get(i)),
        before.checked_sub(1).and_then(|i| pulses.get(i)),
    ) else {
        return Response::Moving;
    };
    if (a.width - b.width).abs() > count_ns / 2.0 {
        return Response::Moving;
    }
    pulses[before..]
        .iter()
        .find(|p| (p.width - b.width).abs() > count_ns * 1.5)
        .map_or(Response::Never, |p| Response::After((p.rise - at) / 1e6))
}

/// The row of `events` (ns) on yaw's pulses in `boot`, at 50 Hz.
pub fn row(name: &'static str, events: &[f64], boot: &Boot) -> Result<Row> {
    row_at(name, events, boot, ServoRate::DEFAULT, GOAL_MS)
}

/// The row of `events` (ns) on yaw's pulses in `boot`, the servos at
/// `rate` (its frames, and its PWM count for the response), with the goal
/// `goal_ms` for p99.
pub fn row_at(
    name: &'static str,
    events: &[f64],
    boot: &Boot,
    rate: ServoRate,
    goal_ms: f64,
) -> Result<Row> {
    let pulses = &pulses::measure(&boot.trains[2]);
    let count_ns = crate::sim::count_ns_at(rate);
    let frame_ns = f64::from(rate.period().0) * 1e3;
    let mut ms = Vec::new();
    let mut worst: Vec<(f64, f64)> = Vec::new();
    let mut skipped = 0;
    let mut phases = [0; 5];
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
    if ms.len() < EVENTS {
        bail!(
            "{name}: {} events measured ({skipped} skipped), fewer than {EVENTS}",
            ms.len()
        );
    }
    ms.sort_by(f64::total_cmp);
    worst.sort_by(|a, b| b.1.total_cmp(&a.1));
    worst.truncate(3);
    Ok(Row {
        name,
        ms,
        skipped,
        phases,
        worst,
        waited_us: port_wait(boot),
        goal_ms,
    })
}

/// The longest a port task waited for the CPU in `boot`, µs: the last
/// `port tasks waited at most <n> us` the image logged (it logs each
/// longer wait within a second).
pub fn port_wait(boot: &Boot) -> Option<u32> {
    boot.log.iter().rev().find_map(|(_, line)| {
        line.message
            .strip_prefix("port tasks waited at most ")?
            .strip_suffix(" us")?
            .parse()
            .ok()
    })
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
    let end = times.last().copied().unwrap_or(start) + Duration::from_millis(500);
    let report = run_shipped(root, metadata, end, wall, |config| {
        config.dmx = Some(dmx_line(&script)?);
        Ok(())
    })?;
    let boot = report.boots.first().context("no boot")?;
    // The first change is the set-up's.
    let events: Vec<f64> = boot.dmx_changes.iter().skip(1).copied().collect();
    if events.len() != times.len() {
        bail!(
            "{} DMX frames carried a change, not {}",
            events.len(),
            times.len()
        );
    }
    row("dmx", &events, boot)
}

/// `latency input edge`: with the idle off, two buttons with a look each
/// pressed in turn; each press's edge against yaw's first pulse that
/// moves (see the [module docs](self)).
pub fn input_edge(root: &Path, metadata: &Metadata, wall: Duration) -> Result<Row> {
    let times = schedule(Duration::from_secs(2), SCHEDULED, PRESS_GAP, 0x2545_f491);
    let events = parse_script(&press_script(&times))?;
    let time = script_time(&events);
    let report = play_script(root, metadata, events, time, wall.max(SCRIPT_WALL))?;
    if !report.problems.is_empty() {
        bail!(
            "the input edge's run failed its checks:\n  {}",
            report.problems.join("\n  ")
        );
    }
    let boot = report.boots.first().context("no boot")?;
    let edges: Vec<f64> = boot
        .drives
        .iter()
        .filter(|&&(_, _, high)| !high)
        .map(|&(ns, _, _)| ns)
        .collect();
    if edges.len() != times.len() {
        bail!("{} presses went out, not {}", edges.len(), times.len());
    }
    row("input edge", &edges, boot)
}

/// The input edge's script: the idle off (it fades out in a second, before
/// the first press), two look buttons, a press at each of `times` (from the
/// first frame), GP2 and GP3 in turn.
fn press_script(times: &[Duration]) -> String {
    let mut text = String::from(
        "0 idle off\n0 input 2 button look 0 2000 100 hold=stay\n0 input 3 button look 0 0 100 hold=stay\n",
    );
    let show = |at: Duration| format!("{}.{:06}", at.as_secs(), at.subsec_micros());
    for (k, &at) in times.iter().enumerate() {
        let pin = 2 + k % 2;
        let _ = writeln!(text, "{} pin {pin} low", show(at));
        let _ = writeln!(text, "{} pin {pin} high", show(at + HELD));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pulse(rise_ms: f64, width_us: f64) -> Measured {
        Measured {
            rise: rise_ms * 1e6,
            width: width_us * 1e3,
        }
    }

    #[test]
    fn the_first_pulse_that_moves_after_a_settled_axis() {
        let count = 312.5;
        let pulses: Vec<Measured> = [1500.0, 1500.0, 1500.0, 1500.3125, 1502.0, 1503.0]
            .iter()
            .enumerate()
            .map(|(k, &w)| pulse(10.0 + 20.0 * k as f64, w))
            .collect();
        // An event at 55 ms: a count of change is noise, 1502 µs moves.
        assert_eq!(response(&pulses, 55e6, count), Response::After(35.0));
        // The axis still moved before 95 ms.
        assert_eq!(response(&pulses, 95e6, count), Response::Moving);
        // Nothing before: no baseline.
        assert_eq!(response(&pulses, 5e6, count), Response::Moving);
        let still = vec![pulse(0.0, 1500.0); 4];
        assert_eq!(response(&still, 30e6, count), Response::Never);
    }

    #[test]
    fn percentiles_and_schedules() {
        let row = Row {
            name: "x",
            ms: (1..=200).map(f64::from).collect(),
            skipped: 0,
            phases: [0; 5],
            worst: Vec::new(),
            waited_us: None,
            goal_ms: GOAL_MS,
        };
        assert_eq!((row.percentile(50.0), row.percentile(99.0)), (100.0, 198.0));
        assert!(
            row.lines()
                .starts_with("latency x p50=100.0 p99=198.0 max=200.0 events=200")
        );
        let times = schedule(Duration::from_secs(1), 100, DMX_GAP, 7);
        assert_eq!(times, schedule(Duration::from_secs(1), 100, DMX_GAP, 7));
        for w in times.windows(2) {
            assert!((DMX_GAP.0..DMX_GAP.1).contains(&w[1].saturating_sub(w[0])));
        }
    }

    #[test]
    fn a_row_misses_its_goal_past_25_ms_or_a_port_wait_past_1_ms() {
        let row = Row {
            name: "x",
            ms: (1..=100).map(f64::from).collect(),
            skipped: 0,
            phases: [0; 5],
            worst: Vec::new(),
            waited_us: Some(300),
            goal_ms: GOAL_MS,
        };
        let miss = row.misses().unwrap();
        assert_eq!(miss, "latency x: p99 99.0 ms over 25 ms");
        assert!(row.lines().contains("where the time goes"));
        assert!(row.lines().contains("port tasks waited at most 300 µs"));
        let fast = Row {
            ms: vec![10.0; 100],
            ..row.clone()
        };
        assert_eq!(fast.misses(), None);
        assert!(!fast.lines().contains("where the time goes"));
        let waited = Row {
            waited_us: Some(1001),
            ..fast.clone()
        };
        assert!(waited.misses().unwrap().contains("waited 1001 µs"));
        let unknown = Row {
            waited_us: None,
            ..fast
        };
        assert!(unknown.misses().unwrap().contains("not logged"));
        let at_200_hz = Row {
            ms: vec![8.5; 100],
            goal_ms: GOAL_200_HZ_MS,
            waited_us: Some(20),
            ..row
        };
        assert_eq!(
            at_200_hz.misses().unwrap(),
            "latency x: p99 8.5 ms over 8 ms"
        );
    }

    #[test]
    fn the_script_presses_at_random_phases() {
        let times = schedule(Duration::from_secs(2), SCHEDULED, PRESS_GAP, 0x2545_f491);
        let events = parse_script(&press_script(&times)).unwrap();
        assert_eq!(events.len(), 3 + 2 * SCHEDULED);
        let presses: Vec<u64> = events[3..].iter().step_by(2).map(|e| e.at_us).collect();
        let releases = events[4..].iter().step_by(2).map(|e| e.at_us);
        for (press, release) in presses.iter().zip(releases) {
            assert_eq!(release - press, 30_000);
        }
        for w in presses.windows(2) {
            assert!((150_000..170_000).contains(&(w[1] - w[0])));
        }
        // Spread over the frame: every fifth of it is hit.
        let phases: Vec<u64> = presses.iter().map(|at| at % 20_000).collect();
        for fifth in 0..5 {
            assert!(phases.iter().any(|p| p / 4000 == fifth));
        }
    }
}
