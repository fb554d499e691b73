//! `cargo xtask bench`: the benchmark image in QEMU, where one instruction
//! is one nanosecond of virtual time. It logs `bench row=<label> n=<N>
//! w=<W> engine=<insns> direct=<insns>` (the boot precompute against a
//! direct-form f32 smoothing) and `frame bench [scenario=…] frames=… min=…
//! median=… max=… max_at=… mean=…` at 50 and 333 Hz; this module prints them and holds the
//! default row to its [`BUDGET`] and each frame row to its ceiling.

// Instruction counts are far below 2^52 and positive: the float conversions are exact.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]

use std::path::Path;

use anyhow::{Context, Result, bail};

mod frame;
pub mod latency;
mod paths;
mod telemetry;
pub mod tracking;

pub use frame::FrameRow;
use frame::frames_over_budget;

use crate::figures::{self, thousands};
use crate::{
    args::Options,
    log::{LogLine, Run},
    project::{self, Image, Metadata, QEMU},
    qemu::{self, Echo},
    setup,
};

/// The benchmark image: bin `bench` of the QEMU package (`qemu/src/bench.rs`).
pub const BENCH: Image = Image::qemu("bench");

/// The budget for the default set (three axes, N = 900, W = 59) at boot:
/// 150,000 instructions, about 1.2 ms on a 125 MHz RP2040. The count is a
/// property of the compiler as much as of the code, which is why
/// rust-toolchain.toml pins the toolchain.
pub const BUDGET: u64 = 150_000;

/// The name of the benchmark's stage in `cargo xtask test`.
pub const STAGE: &str = "QEMU bench: default set within its 150,000-instruction budget, \
                         frame update at 50 and 333 Hz: median within 1,200 idle and 2,000 \
                         with a gesture and a look, max within 4,000";

/// RP2040 system clock (Hz) the time column assumes: 125 MHz, the Pico's default.
const RP2040_HZ: f64 = 125e6;

/// Rows the image must report, in table order.
const LABELS: [&str; 7] = ["default", "w15", "w59", "w239", "n450", "n900", "n1800"];

/// The W rows (N = 900) and the N rows (W = 59).
const W_ROWS: [&str; 3] = ["w15", "w59", "w239"];
const N_ROWS: [&str; 3] = ["n450", "n900", "n1800"];

/// Largest max/min engine count over the W rows still called flat: the
/// engine's smoother is O(N) whatever W is, only the O(W) kernel table and
/// wrap correction grow with W (the direct form grows 16× from W = 15 to 239).
const FLAT_LIMIT: f64 = 1.5;

/// How far the marginal cost per sample may change between N = 450..900 and
/// N = 900..1800 (as a ratio) and still be called linear. The plain ratio
/// n1800/n450 is 4 only without a fixed cost (kernel table, wrap correction,
/// call overhead), which pulls it below 4; the marginal cost ignores that.
const MARGINAL_TOLERANCE: f64 = 0.1;

/// One `bench row=...` line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Row {
    pub label: String,
    pub n: u64,
    pub w: u64,
    /// Instructions of the engine (three axes, whole pipeline).
    pub engine: u64,
    /// Instructions of the direct-form f32 smoothing (three axes).
    pub direct: u64,
}

impl Row {
    /// Parses a `bench row=<label> n=<N> w=<W> engine=<i> direct=<i> (...)`
    /// message; `None` for any other message, an error for a malformed one.
    pub fn parse(message: &str) -> Result<Option<Self>> {
        let Some(rest) = message.trim_start().strip_prefix("bench ") else {
            return Ok(None);
        };
        let field = |key: &str| -> Result<&str> {
            rest.split_whitespace()
                .find_map(|token| token.strip_prefix(key)?.strip_prefix('='))
                .with_context(|| format!("`{message}` has no `{key}=`"))
        };
        let number = |key: &str| -> Result<u64> {
            let value = field(key)?;
            value
                .replace('_', "")
                .parse()
                .with_context(|| format!("`{key}={value}` in `{message}` is not a whole number"))
        };
        Ok(Some(Self {
            label: field("row")?.to_owned(),
            n: number("n")?,
            w: number("w")?,
            engine: number("engine")?,
            direct: number("direct")?,
        }))
    }

    /// direct / engine.
    pub fn ratio(&self) -> f64 {
        self.direct as f64 / self.engine as f64
    }
}

/// The rows of a benchmark log, in order; fails on a malformed line.
pub fn rows(log: &[LogLine]) -> Result<Vec<Row>> {
    log.iter()
        .filter_map(|line| Row::parse(&line.message).transpose())
        .collect()
}

/// What the rows say: the budget, flatness in W and linearity in N.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// Engine instructions of the `default` row.
    pub default: u64,
    /// max/min of the engine counts over the W rows.
    pub flatness: f64,
    /// engine(n1800) / engine(n450): 4 if the cost is proportional to N.
    pub linearity: f64,
    /// Marginal engine instructions per unit of N (three axes) from N = 450
    /// to 900 and from 900 to 1800.
    pub marginal: [f64; 2],
    /// The fixed cost this implies: engine(n450) − 450 × the first marginal cost.
    pub fixed: f64,
}

impl Verdict {
    /// Reads the verdict from the rows; fails if a row it needs is missing.
    pub fn of(rows: &[Row]) -> Result<Self> {
        let engine = |label: &str| -> Result<u64> {
            rows.iter()
                .find(|row| row.label == label)
                .map(|row| row.engine)
                .with_context(|| format!("the benchmark reported no `{label}` row"))
        };
        let w_counts = W_ROWS
            .iter()
            .map(|label| engine(label))
            .collect::<Result<Vec<_>>>()?;
        let [n450, n900, n1800] = N_ROWS.map(engine);
        let (n450, n900, n1800) = (n450? as f64, n900? as f64, n1800? as f64);
        let max = w_counts.iter().copied().max().unwrap_or(0);
        let min = w_counts.iter().copied().min().unwrap_or(0).max(1);
        Ok(Self {
            default: engine("default")?,
            flatness: max as f64 / min as f64,
            linearity: n1800 / n450.max(1.0),
            marginal: [(n900 - n450) / 450.0, (n1800 - n900) / 900.0],
            fixed: n450 - (n900 - n450),
        })
    }

    /// The default row meets the [`BUDGET`].
    pub fn within_budget(&self) -> bool {
        self.default <= BUDGET
    }

    /// The engine count hardly depends on W.
    pub fn flat(&self) -> bool {
        self.flatness <= FLAT_LIMIT
    }

    /// The engine count grows linearly with N: the same marginal cost per
    /// sample over both steps of N.
    pub fn linear(&self) -> bool {
        let [a, b] = self.marginal;
        a > 0.0 && b > 0.0 && (b / a - 1.0).abs() <= MARGINAL_TOLERANCE
    }

    /// The verdict, one check a line.
    pub fn lines(&self) -> String {
        let mark = |ok: bool| if ok { "ok" } else { "NO" };
        let [a, b] = self.marginal;
        format!(
            "verdict:\n\
             \x20 budget: default = {} insn against {}: {} ({:.1} % of the budget, \
             {} to spare)\n\
             \x20 flat in W: max/min over W = 15, 59, 239 is {:.2} (limit {FLAT_LIMIT}): {}\n\
             \x20 linear in N: n1800/n450 = {:.2} (4 if proportional); marginal cost \
             {a:.1} insn per unit of N from 450 to 900, {b:.1} from 900 to 1800 \
             (ratio {:.3}, limit 1 ± {MARGINAL_TOLERANCE}): {}; fixed cost ≈ {} insn\n",
            thousands(self.default),
            thousands(BUDGET),
            if self.within_budget() { "ok" } else { "OVER" },
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

/// Fails if the run or the log is broken, or (unless `no_budget`) if the
/// default row or a frame row is over its budget. `smoke`: the QEMU smoke
/// image's plain run, if the caller made it (the telemetry check compares
/// against it; without, it runs the image itself).
pub fn run_and_check(
    root: &Path,
    metadata: &Metadata,
    options: Options,
    smoke: Option<&Run>,
) -> Result<()> {
    BENCH.build(root)?;
    let elf = BENCH.elf(metadata);
    let run = qemu::run(&elf, options.timeout, Echo::Problems)?;
    println!("{}", run.describe());
    if !run.succeeded() {
        bail!("{}", run.describe());
    }
    let rows = rows(&run.log)?;
    let missing: Vec<&str> = LABELS
        .into_iter()
        .filter(|label| !rows.iter().any(|row| row.label == *label))
        .collect();
    if !missing.is_empty() {
        bail!("the benchmark reported no row for {}", missing.join(", "));
    }
    let verdict = Verdict::of(&rows)?;
    print!("{}", verdict.lines());
    let frames = FrameRow::all(&run.log)?;
    record_figures(&rows, &frames, BUDGET);
    println!();
    QEMU.build(root)?;
    println!(
        "{}",
        telemetry::check(&QEMU.elf(metadata), options.timeout, smoke)?
    );
    if let Some(over) = frames_over_budget(&frames) {
        if options.no_budget {
            println!("(--no-budget: the frame ceilings are reported, not enforced)");
        } else {
            bail!("{over} (pass --no-budget to report without failing)");
        }
    }
    if !verdict.within_budget() {
        if options.no_budget {
            println!("(--no-budget: the budget is reported, not enforced)");
        } else {
            bail!(
                "the default set takes {} instructions, over its budget of {} \
                 (pass --no-budget to report without failing)",
                thousands(verdict.default),
                thousands(BUDGET)
            );
        }
    }
    Ok(())
}

/// `cargo xtask bench`. `Ok(false)` when the benchmark failed.
pub fn command(options: Options) -> Result<bool> {
    let root = project::root();
    setup::ensure_toolchain(&root)?;
    setup::ensure_qemu()?;
    let metadata = project::metadata(&root)?;
    let mut passed = match run_and_check(&root, &metadata, options, None) {
        Ok(()) => true,
        Err(error) => {
            println!("bench FAILED: {error:#}");
            false
        }
    };
    // How the head follows people, in the host trace.
    println!();
    if let Err(error) = tracking::stage() {
        println!("tracking FAILED: {error:#}");
        passed = false;
    }
    // The latency rows: the shipped image in the RP2040 emulator
    // (`bench/latency.rs`).
    println!();
    if let Err(error) = latency_stage(&root, &metadata) {
        println!("latency FAILED: {error:#}");
        passed = false;
    }
    Ok(passed)
}

/// The latency stage's name in `cargo xtask test`.
pub const LATENCY_STAGE: &str = "latency in the RP2040 emulator: at 50 Hz a look over USB and \
     UART0, an input edge, DMX and a Bottango curve each on the servos within 25 ms at p99, at \
     200 Hz a look over UART0 within 8 ms; no port task waits more than 1 ms for the CPU";

/// Every latency row, printed and recorded; fails if a row misses its goal
/// (or could not be measured).
pub fn latency_stage(root: &Path, metadata: &Metadata) -> Result<()> {
    let mut figures = Vec::new();
    let mut misses = Vec::new();
    // The runs are independent emulators: as many at once as there are
    // cores.
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    let mut results = Vec::new();
    for batch in latency::PATHS.chunks(cores) {
        std::thread::scope(|scope| {
            let runs: Vec<_> = batch
                .iter()
                .map(|path| scope.spawn(|| path(root, metadata, crate::sim::WALL)))
                .collect();
            for run in runs {
                results.push(
                    run.join()
                        .unwrap_or_else(|_| Err(anyhow::anyhow!("a latency run panicked"))),
                );
            }
        });
    }
    for result in results {
        match result {
            Ok(row) => {
                print!("{}", row.lines());
                figures.push(row.figure());
                misses.extend(row.misses());
            }
            Err(error) => misses.push(format!("{error:#}")),
        }
    }
    record_latency(figures);
    if misses.is_empty() {
        Ok(())
    } else {
        bail!("{}", misses.join("; "))
    }
}

/// The latency rows, for the measured figures.
fn record_latency(rows: Vec<Vec<String>>) {
    let intro = "Latency, measured in the RP2040 emulator on the shipped image, from an event \
                 to the first servo pulse that shows it, in ms \
                 ([the emulators](../dev/emulators.md#latency-of-an-input-edge)).";
    let header = [
        "row",
        "events",
        "p50",
        "p99",
        "max",
        "goal (p99)",
        "longest wait of a port task for the CPU",
    ];
    figures::record("latency", intro.to_owned(), &header, rows);
}

/// The benchmark's rows, for the measured figures.
fn record_figures(rows: &[Row], frames: &[FrameRow], budget: u64) {
    let at_125_mhz = |insns: u64| insns as f64 / RP2040_HZ * 1e6;
    let intro = "Instructions of one frame update (`FrameLoop::write`: playback, mixer, fade, \
                 limits, mapping, three PWM writes) over every frame of a whole loop, counted \
                 exactly in QEMU ([what a frame costs](limiter.md#what-a-frame-costs)), at 50 Hz \
                 (a 20 ms frame: 2,500,000 cycles of a 125 MHz RP2040) and 333 Hz (3003 µs: \
                 375,375 cycles). The CPU load is the mean frame at one cycle an instruction \
                 over the frame period: a lower bound.";
    let header = [
        "row",
        "rate",
        "frames",
        "min",
        "median",
        "max",
        "mean",
        "ceiling (median / max)",
        "median at 125 MHz",
        "CPU load",
    ];
    // Each with its ceiling: `FrameRow::all` refused a row without one.
    let cells = frames.iter().filter_map(|row| {
        let ceiling = row.ceiling()?;
        let counts = [row.frames, row.min, row.median, row.max, row.mean].map(thousands);
        let mut cells = vec![row.label(), format!("{} Hz", row.rate)];
        cells.extend(counts);
        cells.push(format!(
            "{} / {}",
            thousands(ceiling.median),
            thousands(ceiling.max)
        ));
        cells.push(format!("≥ {:.1} µs", at_125_mhz(row.median)));
        cells.push(format!("≥ {:.3} %", row.load_percent()));
        Some(cells)
    });
    figures::record("frames", intro.to_owned(), &header, cells.collect());
    let intro = format!(
        "Instructions of the three axes' loops, computed at boot, for the default set and \
         across W and N, next to a direct-form f32 implementation of the paper's smoothing \
         on the same core ([how it is computed](motion.md#how-it-is-computed)). The default \
         set's ceiling is {} instructions.",
        thousands(budget)
    );
    let header = [
        "row",
        "N",
        "W",
        "engine",
        "direct f32 smoothing",
        "ratio",
        "engine at 125 MHz",
    ];
    let cells = rows.iter().map(|row| {
        vec![
            row.label.clone(),
            row.n.to_string(),
            row.w.to_string(),
            thousands(row.engine),
            thousands(row.direct),
            format!("{:.0}×", row.ratio()),
            format!("≥ {:.2} ms", at_125_mhz(row.engine) / 1000.0),
        ]
    });
    figures::record("precompute", intro, &header, cells.collect());
}

#[cfg(test)]
mod tests;
