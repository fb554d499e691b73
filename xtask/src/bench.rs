//! `cargo xtask bench`: the benchmark image in QEMU (one instruction, one ns
//! of virtual time). Its `bench row=…` lines (boot precompute) are held to
//! [`BUDGET`], its `frame bench …` lines to [`CEILINGS`], the frame work to
//! its own with telemetry streaming; then the tracking and latency rows.

// Instruction counts are far below 2^52 and positive: the float conversions are exact.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]

use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};

pub mod latency;
mod paths;
pub mod tracking;

pub use paths::stage as latency_stage;

use crate::console::{Pace, qemu_session};
use crate::figures::{self, thousands};
use crate::log::{LogLine, Run, field, number};
use crate::{
    args::Options,
    project::{self, Image, Metadata, QEMU},
    qemu::{self, Echo},
    setup,
};

/// The benchmark image: bin `bench` of the QEMU package (`boards/qemu/src/bench.rs`).
pub const BENCH: Image = Image::qemu("bench");

/// The default set's budget (three axes, N = 900, W = 59) at boot, about
/// 1.2 ms on a 125 MHz RP2040. The count depends on the compiler as much as
/// on the code: rust-toolchain.toml pins the toolchain.
pub const BUDGET: u64 = 150_000;

/// The name of the benchmark's stage in `cargo xtask test`.
pub const STAGE: &str = "QEMU bench: default set within its 150,000-instruction budget, \
                         frame update at 50 and 333 Hz: median within 1,200 idle (1,300 at 333 Hz) and 2,000 \
                         with a gesture and a look, max within 4,000";

/// The latency stage's name in `cargo xtask test`.
pub const LATENCY_STAGE: &str = "latency in the RP2040 emulator: at 50 Hz a look over USB and \
     UART0, an input edge, DMX and a Bottango curve each on the servos within 25 ms at p99, at \
     200 Hz a look over UART0 within 8 ms; no port task waits more than 1 ms for the CPU";

/// The Pico's default system clock, Hz, which the time columns assume.
const RP2040_HZ: f64 = 125e6;

/// Largest max/min engine count over the W rows still called flat: the
/// engine's smoother is O(N) whatever W is (the direct form grows 16× from
/// W = 15 to 239).
const FLAT_LIMIT: f64 = 1.5;

/// How far the marginal cost per sample may change between N = 450..900 and
/// 900..1800 (as a ratio) and still be called linear; the plain ratio
/// n1800/n450 is pulled below 4 by the fixed cost.
const MARGINAL_TOLERANCE: f64 = 0.1;

fn numbers<const N: usize>(message: &str, keys: [&str; N]) -> Result<[u64; N]> {
    let mut out = [0; N];
    for (value, key) in out.iter_mut().zip(keys) {
        *value = number(message, key)?;
    }
    Ok(out)
}

/// One `bench row=...` line: instructions of the engine (three axes, the
/// whole pipeline) and of the direct-form f32 smoothing (three axes).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Row {
    pub label: String,
    pub n: u64,
    pub w: u64,
    pub engine: u64,
    pub direct: u64,
}

/// The benchmark rows of a log, in order; fails on a malformed one.
pub fn rows(log: &[LogLine]) -> Result<Vec<Row>> {
    let rows = log.iter().filter(|l| l.message.starts_with("bench "));
    let row = |m: &str| -> Result<Row> {
        let label = field(m, "row").with_context(|| format!("`{m}` has no `row=`"))?;
        let [n, w, engine, direct] = numbers(m, ["n", "w", "engine", "direct"])?;
        Ok(Row {
            label: label.to_owned(),
            n,
            w,
            engine,
            direct,
        })
    };
    rows.map(|line| row(&line.message)).collect()
}

/// What the rows say: the `default` row's engine count; max/min over the W
/// rows; n1800/n450 (4 if proportional to N); the marginal cost per unit of
/// N from 450 to 900 and from 900 to 1800; the fixed cost this implies.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    pub default: u64,
    pub flatness: f64,
    pub linearity: f64,
    pub marginal: [f64; 2],
    pub fixed: f64,
}

impl Verdict {
    pub fn of(rows: &[Row]) -> Result<Self> {
        let engine = |label: &str| -> Result<f64> {
            let row = rows.iter().find(|row| row.label == label);
            row.map(|row| row.engine as f64)
                .with_context(|| format!("the benchmark reported no `{label}` row"))
        };
        let [w15, w59, w239] = [engine("w15")?, engine("w59")?, engine("w239")?];
        let [n450, n900, n1800] = [engine("n450")?, engine("n900")?, engine("n1800")?];
        let (max, min) = (w15.max(w59).max(w239), w15.min(w59).min(w239));
        Ok(Self {
            default: engine("default")? as u64,
            flatness: max / min.max(1.0),
            linearity: n1800 / n450.max(1.0),
            marginal: [(n900 - n450) / 450.0, (n1800 - n900) / 900.0],
            fixed: n450 - (n900 - n450),
        })
    }

    /// The engine count hardly depends on W.
    pub fn flat(&self) -> bool {
        self.flatness <= FLAT_LIMIT
    }

    /// The same marginal cost per sample over both steps of N.
    pub fn linear(&self) -> bool {
        let [a, b] = self.marginal;
        a > 0.0 && b > 0.0 && (b / a - 1.0).abs() <= MARGINAL_TOLERANCE
    }

    /// The verdict, one check a line.
    pub fn lines(&self) -> String {
        let mark = |ok: bool| if ok { "ok" } else { "NO" };
        let [a, b] = self.marginal;
        format!(
            "verdict:\n  budget: default = {} insn against {}: {} ({:.1} % of the budget, {} to spare)\n  \
             flat in W: max/min over W = 15, 59, 239 is {:.2} (limit {FLAT_LIMIT}): {}\n  \
             linear in N: n1800/n450 = {:.2} (4 if proportional); marginal cost {a:.1} insn per \
             unit of N from 450 to 900, {b:.1} from 900 to 1800 (ratio {:.3}, limit 1 ± \
             {MARGINAL_TOLERANCE}): {}; fixed cost ≈ {} insn\n",
            thousands(self.default),
            thousands(BUDGET),
            if self.default <= BUDGET { "ok" } else { "OVER" },
            self.default as f64 / BUDGET as f64 * 100.0,
            thousands(BUDGET.saturating_sub(self.default)),
            self.flatness,
            mark(self.flat()),
            self.linearity,
            b / a,
            mark(self.linear()),
            thousands(self.fixed.max(0.0).round() as u64),
        )
    }
}

/// The frame rows the image must report, by rate (Hz) and scenario, with
/// their ceilings on the median and the max (idle: about 10 µs; at 333 Hz
/// the duty is counted from the exact angle).
pub const CEILINGS: [(u64, Option<&str>, [u64; 2]); 4] = [
    (50, None, [1200, 4000]),
    (50, Some("gesture+look"), [2000, 4000]),
    (333, None, [1300, 4000]),
    (333, Some("gesture+look"), [2000, 4000]),
];

/// A `frame bench ...` line: instructions per frame update over a loop at
/// the servo rate `rate` (Hz; 50 in a log without `rate=`), with `scenario`
/// playing over the idle (if any); the line's `max_at` is not kept.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameRow {
    pub rate: u64,
    pub scenario: Option<String>,
    pub frames: u64,
    pub min: u64,
    pub median: u64,
    pub max: u64,
    pub mean: u64,
}

impl FrameRow {
    /// The frame rows of a benchmark log; fails if one is missing or
    /// malformed, or is none of [`CEILINGS`]' scenarios.
    pub fn all(log: &[LogLine]) -> Result<Vec<Self>> {
        let lines = log
            .iter()
            .filter_map(|l| l.message.strip_prefix("frame bench "));
        let row = |m: &str| -> Result<Self> {
            let keys = ["frames", "min", "median", "max", "mean"];
            let [frames, min, median, max, mean] = numbers(m, keys)?;
            let rate = field(m, "rate").map_or(Ok(50), |_| number(m, "rate"))?;
            let scenario = field(m, "scenario").map(str::to_owned);
            Ok(Self {
                rate,
                scenario,
                frames,
                min,
                median,
                max,
                mean,
            })
        };
        let rows: Vec<Self> = lines.map(row).collect::<Result<_>>()?;
        for (rate, scenario, _) in CEILINGS {
            if !(rows.iter()).any(|row| row.rate == rate && row.scenario.as_deref() == scenario) {
                let scenario = scenario.map_or(String::new(), |s| format!(" scenario={s}"));
                bail!("the benchmark reported no `frame bench rate={rate}{scenario}` line");
            }
        }
        if let Some(row) = rows.iter().find(|row| row.ceiling().is_none()) {
            let label = row.label();
            bail!("the benchmark reported a frame row without a ceiling: `{label}`");
        }
        Ok(rows)
    }

    /// This row's `[median, max]` ceiling, if its rate and scenario have one.
    pub fn ceiling(&self) -> Option<[u64; 2]> {
        let own = (self.rate, self.scenario.as_deref());
        CEILINGS.iter().find(|c| (c.0, c.1) == own).map(|c| c.2)
    }

    /// The median and the max within this row's ceiling (a row without
    /// one is not).
    pub fn within_budget(&self) -> bool {
        self.ceiling()
            .is_some_and(|[median, max]| self.median <= median && self.max <= max)
    }

    /// `frame`, or `frame (gesture + look)`; at another rate than 50 Hz,
    /// with it: `frame at 333 Hz`.
    pub fn label(&self) -> String {
        let scenario = (self.scenario.as_ref()).map(|s| format!(" ({})", s.replace('+', " + ")));
        let rate = (self.rate != 50).then(|| format!(" at {} Hz", self.rate));
        let (scenario, rate) = (scenario.unwrap_or_default(), rate.unwrap_or_default());
        format!("frame{scenario}{rate}")
    }

    /// The share of the CPU the frame update takes at the row's rate, %:
    /// the mean frame at one 125 MHz cycle an instruction (a lower bound)
    /// over the frame period (rounded to whole µs: 3003 at 333 Hz).
    pub fn load_percent(&self) -> f64 {
        let period_us = (1_000_000 + self.rate / 2) / self.rate.max(1);
        self.mean as f64 / RP2040_HZ * 1e6 / period_us as f64 * 100.0
    }
}

/// The frame rows over their ceilings, each named with its numbers and
/// ceiling; `None` if every row is within its own.
pub fn frames_over_budget(frames: &[FrameRow]) -> Option<String> {
    let over: Vec<String> = (frames.iter().filter(|frame| !frame.within_budget()))
        .map(|frame| {
            let ceiling = frame.ceiling().map_or_else(
                || "no ceiling".to_owned(),
                |[median, max]| format!("ceiling {} and {}", thousands(median), thousands(max)),
            );
            let (label, median) = (frame.label(), thousands(frame.median));
            let max = thousands(frame.max);
            format!(
                "row `{label}` takes {median} instructions at the median and {max} at most \
                 ({ceiling})"
            )
        })
        .collect();
    (!over.is_empty()).then(|| format!("frame update over its ceiling: {}", over.join("; ")))
}

/// Fails if the run or the log is broken, or (unless `no_budget`) if the
/// default row or a frame row is over its budget. `smoke`: the QEMU smoke
/// image's plain run, if the caller made it (for the telemetry check).
pub fn run_and_check(
    root: &Path,
    metadata: &Metadata,
    options: Options,
    smoke: Option<&Run>,
) -> Result<()> {
    BENCH.build(root)?;
    let run = qemu::run(&BENCH.elf(metadata), options.timeout, Echo::Problems)?;
    println!("{}", run.describe());
    if !run.succeeded() {
        bail!("{}", run.describe());
    }
    // The verdict needs every row: the default, across W and across N.
    let rows = rows(&run.log)?;
    let verdict = Verdict::of(&rows)?;
    print!("{}", verdict.lines());
    let frames = FrameRow::all(&run.log)?;
    record_figures(&rows, &frames);
    QEMU.build(root)?;
    let telemetry = telemetry_check(&QEMU.elf(metadata), options.timeout, smoke)?;
    println!("\n{telemetry}");
    let mut over = frames_over_budget(&frames).into_iter().collect::<Vec<_>>();
    if verdict.default > BUDGET {
        let (default, budget) = (thousands(verdict.default), thousands(BUDGET));
        over.push(format!(
            "the default set takes {default} instructions, over its budget of {budget}"
        ));
    }
    let over = over.join("; ");
    if over.is_empty() {
        return Ok(());
    }
    if !options.no_budget {
        bail!("{over} (pass --no-budget to report without failing)");
    }
    println!("(--no-budget: the ceilings are reported, not enforced: {over})");
    Ok(())
}

/// `cargo xtask bench`: the rows in QEMU, the tracking figures in the host
/// trace, then the latency rows in the RP2040 emulator. `Ok(false)` when
/// any failed.
pub fn command(options: Options) -> Result<bool> {
    let (root, metadata) = setup::prepare()?;
    setup::ensure_qemu()?;
    let results = [
        ("bench", run_and_check(&root, &metadata, options, None)),
        ("tracking", tracking::stage()),
        ("latency", paths::stage(&root, &metadata)),
    ];
    let passed = results.map(|(what, result)| project::passed(what, &result));
    Ok(!passed.contains(&false))
}

/// The benchmark's rows, for the measured figures.
fn record_figures(rows: &[Row], frames: &[FrameRow]) {
    let at_125_mhz = |insns: u64| insns as f64 / RP2040_HZ * 1e6;
    let intro = "Instructions of one frame update (`FrameLoop::write`: playback, mixer, fade, \
                 limits, mapping, three PWM writes) over every frame of a whole loop, counted \
                 exactly in QEMU ([what a frame costs](limiter.md#what-a-frame-costs)), at 50 Hz \
                 (a 20 ms frame: 2,500,000 cycles of a 125 MHz RP2040) and 333 Hz (3003 µs: \
                 375,375 cycles). The CPU load is the mean frame at one cycle an instruction \
                 over the frame period: a lower bound.";
    let header = "row|rate|frames|min|median|max|mean|ceiling (median / max)|median at 125 MHz|\
                  CPU load";
    // Each with its ceiling: `FrameRow::all` refused a row without one.
    let cells = frames.iter().filter_map(|row| {
        let [median, max] = row.ceiling()?;
        let mut cells = vec![row.label(), format!("{} Hz", row.rate)];
        cells.extend([row.frames, row.min, row.median, row.max, row.mean].map(thousands));
        cells.push(format!("{} / {}", thousands(median), thousands(max)));
        cells.push(format!("≥ {:.1} µs", at_125_mhz(row.median)));
        cells.push(format!("≥ {:.3} %", row.load_percent()));
        Some(cells)
    });
    let header: Vec<&str> = header.split('|').collect();
    figures::record("frames", intro.to_owned(), &header, cells.collect());
    let intro = format!(
        "Instructions of the three axes' loops, computed at boot, for the default set and \
         across W and N, next to a direct-form f32 implementation of the paper's smoothing \
         on the same core ([how it is computed](motion.md#how-it-is-computed)). The default \
         set's ceiling is {} instructions.",
        thousands(BUDGET)
    );
    let header = "row|N|W|engine|direct f32 smoothing|ratio|engine at 125 MHz";
    let header: Vec<&str> = header.split('|').collect();
    let cells = rows.iter().map(|row| {
        vec![
            row.label.clone(),
            row.n.to_string(),
            row.w.to_string(),
            thousands(row.engine),
            thousands(row.direct),
            format!("{:.0}×", row.direct as f64 / row.engine as f64),
            format!("≥ {:.2} ms", at_125_mhz(row.engine) / 1000.0),
        ]
    });
    figures::record("precompute", intro, &header, cells.collect());
}

/// Instructions per `SysTick` count in the smoke run (12.5 MHz after reset
/// under `-icount shift=0`, `boards/qemu/src/systick.rs`).
const INSNS_PER_COUNT: u64 = 80;

/// Telemetry lines to see before the host hangs up: the schedule's
/// fade-out starts at frame 1800, a line every 20 frames.
const LINES: usize = 80;

/// The console's input after `watch 50`: nothing until [`LINES`] telemetry
/// lines came (or the deadline passed), then the end (the host hangs up).
struct Streaming<'a> {
    seen: &'a AtomicUsize,
    deadline: Instant,
}

impl Read for Streaming<'_> {
    fn read(&mut self, _: &mut [u8]) -> std::io::Result<usize> {
        while self.seen.load(Ordering::Acquire) < LINES && Instant::now() < self.deadline {
            std::thread::sleep(Duration::from_millis(5));
        }
        Ok(0)
    }
}

/// What a run logged of its frame work: `(average, at most)`.
fn frame_work(log: &[LogLine]) -> Result<(u64, u64)> {
    let line = log
        .iter()
        .find_map(|l| l.message.strip_prefix("frame work: "));
    let line = line.context("the run logged no frame work")?;
    let words = line.split(|c: char| !c.is_ascii_digit());
    let mut numbers = words.filter(|w| !w.is_empty()).map(str::parse);
    match (numbers.next(), numbers.next()) {
        (Some(Ok(average)), Some(Ok(most))) => Ok((average, most)),
        _ => bail!("unreadable frame work line: {line}"),
    }
}

/// The smoke image `elf` with `watch 50` streaming on UART0 against its
/// plain run (`plain`, else run here): the frame work it logs must stay
/// within one `SysTick` count (telemetry is off the frame path).
fn telemetry_check(elf: &Path, timeout: Duration, plain: Option<&Run>) -> Result<String> {
    let without = match plain {
        Some(run) => frame_work(&run.log)?,
        None => frame_work(&qemu::run(elf, timeout, Echo::Problems)?.log)?,
    };
    let seen = AtomicUsize::new(0);
    let input = b"watch 50\n".chain(Streaming {
        seen: &seen,
        deadline: Instant::now() + timeout,
    });
    let mut count = |line: &[u8]| {
        if line.starts_with(b"~ ") {
            seen.fetch_add(1, Ordering::AcqRel);
        }
    };
    let wait = Duration::from_secs(5);
    let (run, _) = qemu_session(elf, input, &mut count, Pace::Fast, Echo::Problems, wait)?;
    let lines = seen.load(Ordering::Acquire);
    let with = frame_work(&run.log)?;
    let verdict = qemu::check_summary(&run.log)?;
    if lines < LINES {
        bail!("telemetry: only {lines} lines streamed during the run");
    }
    let line = format!(
        "telemetry: the smoke schedule with `watch 50` streaming on UART0 ({lines} lines): \
         frame work {} instructions on average, at most {} (without: {}, {}); {verdict}",
        with.0, with.1, without.0, without.1
    );
    let count = INSNS_PER_COUNT;
    if with.0.abs_diff(without.0) > count || with.1.abs_diff(without.1) > count {
        bail!(
            "{line}: telemetry changed the frame work by more than one count ({count} instructions)"
        );
    }
    Ok(format!(
        "{line}\ntelemetry adds nothing to the frame path (within one count of {count} \
         instructions): it is written by the console task, and the frame rows above hold with \
         `watch 50` running"
    ))
}

#[cfg(test)]
mod tests;
