//! `cargo xtask metrics`: the distributions of the loop metrics over many
//! seeds, both closures. Seed i is `i · 2654435761 + 12345` mod 2³² (spread
//! over the `u32` range) on axis i mod 3 with its default row; each loop is
//! generated as the firmware does and measured by [`LoopMetrics`]. Range
//! columns are relative to the loop's own [α1, α2]; percentiles are
//! nearest-rank.

// Counts and angles are small: float conversions are exact or harmless.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]

use std::{fmt::Write as _, thread, time::Instant};

use anyhow::{Context, Result, anyhow};
use idle_head_core::{
    Angle, Axis,
    metrics::LoopMetrics,
    motion::{AxisConfig, AxisError, Closure, DEFAULT_HEAD, HannKernel, Mdeg16, generate_into},
};

use crate::args::LoopShape;
use crate::figures;

/// The continuity ratio a loop must not exceed (max over P95, both d1 and d2).
pub const CONTINUITY_LIMIT: f32 = 3.0;

/// Options of `cargo xtask metrics` (its help text is in `cli.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::Args)]
pub struct Args {
    /// Seeds per closure.
    #[arg(
        long,
        value_name = "count",
        allow_negative_numbers = true,
        default_value_t = 10_000,
        value_parser = crate::args::at_least_one::<u32>
    )]
    pub seeds: u32,
    #[command(flatten)]
    pub shape: LoopShape,
}

impl Args {
    /// The command line that reproduces this run.
    pub fn command_line(&self) -> String {
        format!(
            "cargo xtask metrics --seeds {} --n {} --w {}",
            self.seeds,
            self.shape.n(),
            self.shape.w()
        )
    }
}

/// Seed number `i`: `i · 2654435761 + 12345` mod 2³².
pub const fn seed(i: u32) -> u32 {
    i.wrapping_mul(2_654_435_761).wrapping_add(12_345)
}

/// The configuration of seed number `i`: axis i mod 3 with its default row.
pub fn config(i: u32, args: Args, closure: Closure) -> (Axis, AxisConfig) {
    let axis = Axis::ALL[(i % 3) as usize];
    let cfg = DEFAULT_HEAD
        .axis(axis)
        .with_seed(seed(i))
        .with_window(args.shape.w())
        .with_closure(closure);
    (axis, cfg)
}

/// The measured values of one loop, in table order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    pub velocity: f64,
    pub acceleration: f64,
    pub liveliness: f64,
    pub below: f64,
    pub above: f64,
    pub start: f64,
}

impl Measured {
    fn of(metrics: &LoopMetrics, cfg: &AxisConfig) -> Self {
        let deg = |a: Angle| f64::from(a.millidegrees()) / f64::from(Angle::SCALE);
        Self {
            velocity: f64::from(metrics.velocity_ratio),
            acceleration: f64::from(metrics.acceleration_ratio),
            liveliness: f64::from(metrics.liveliness),
            below: deg(metrics.min) - deg(cfg.range.min),
            above: deg(cfg.range.max) - deg(metrics.max),
            start: deg(metrics.start),
        }
    }

    pub(crate) fn discontinuous(&self) -> bool {
        let limit = f64::from(CONTINUITY_LIMIT);
        self.velocity > limit || self.acceleration > limit
    }
}

/// Reads one value of a [`Measured`].
pub(crate) type Getter = fn(&Measured) -> f64;

/// The table rows: name and how to read the value.
pub(crate) const ROWS: [(&str, Getter); 6] = [
    ("max|d1|/P95|d1|", |m| m.velocity),
    ("max|d2|/P95|d2|", |m| m.acceleration),
    ("liveliness", |m| m.liveliness),
    ("min − α1 (°)", |m| m.below),
    ("α2 − max (°)", |m| m.above),
    ("start x(0) (°)", |m| m.start),
];

/// Nearest-rank percentile `q` (0..=1) of sorted values.
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1]
}

/// min, median, p99, max of `values`.
pub fn distribution(mut values: Vec<f64>) -> [f64; 4] {
    values.sort_by(f64::total_cmp);
    [
        percentile(&values, 0.0),
        percentile(&values, 0.5),
        percentile(&values, 0.99),
        percentile(&values, 1.0),
    ]
}

/// Everything measured for one closure.
#[derive(Debug, Default)]
pub struct Results {
    /// One entry per measured seed.
    pub loops: Vec<Measured>,
    /// Seeds the engine rejected (for example a flat walk), with the reason.
    pub rejected: Vec<(u32, String)>,
}

/// Generates and measures seeds `range` for `closure`.
fn measure(range: std::ops::Range<u32>, args: Args, closure: Closure) -> Result<Results> {
    let kernel = HannKernel::new(args.shape.w())?;
    let mut buffer = vec![Mdeg16(0); args.shape.n()];
    let mut scratch = vec![0; args.shape.n()];
    let mut results = Results::default();
    for i in range {
        let (axis, cfg) = config(i, args, closure);
        match generate_into(&mut buffer, &cfg, axis, &kernel, &mut ()) {
            Ok(_) => {
                let metrics = LoopMetrics::measure(&buffer, &mut scratch)
                    .context("the loop is too short to measure")?;
                results.loops.push(Measured::of(&metrics, &cfg));
            }
            Err(error) => results.rejected.push((seed(i), error.to_string())),
        }
    }
    Ok(results)
}

/// Measures every seed for `closure` on all available cores.
pub fn run(args: Args, closure: Closure) -> Result<Results> {
    let threads = thread::available_parallelism()
        .map_or(1, usize::from)
        .max(1) as u32;
    let chunk = args.seeds.div_ceil(threads);
    let parts: Vec<Result<Results>> = thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let start = (t * chunk).min(args.seeds);
                let end = (start + chunk).min(args.seeds);
                scope.spawn(move || measure(start..end, args, closure))
            })
            .collect();
        handles
            .into_iter()
            .map(|handle| {
                handle
                    .join()
                    .unwrap_or_else(|_| Err(anyhow!("a worker thread panicked")))
            })
            .collect()
    });
    let mut all = Results::default();
    for part in parts {
        let part = part?;
        all.loops.extend(part.loops);
        all.rejected.extend(part.rejected);
    }
    Ok(all)
}

/// The violation counts of both closures (their distributions are the
/// tables [`record_figures`] prints).
pub fn report(results: &[(Closure, Results)], args: Args) -> String {
    let mut out = String::new();
    for (closure, result) in results {
        let name = match closure {
            Closure::Paper => "paper",
            Closure::Seamless => "seamless",
        };
        let count = |f: fn(&Measured) -> bool| result.loops.iter().filter(|m| f(m)).count();
        let limit = f64::from(CONTINUITY_LIMIT);
        let _ = writeln!(
            out,
            "{name:<9} continuity > {CONTINUITY_LIMIT}: {} of {} seeds \
             (velocity {}, acceleration {}); outside [α1, α2]: {}; start ≠ 0: {}; rejected: {}",
            count(Measured::discontinuous),
            args.seeds,
            result.loops.iter().filter(|m| m.velocity > limit).count(),
            result
                .loops
                .iter()
                .filter(|m| m.acceleration > limit)
                .count(),
            count(|m| m.below < 0.0 || m.above < 0.0),
            count(|m| m.start != 0.0),
            result.rejected.len(),
        );
        for (seed, reason) in result.rejected.iter().take(3) {
            let _ = writeln!(out, "          rejected seed {seed}: {reason}");
        }
    }
    out
}

/// `cargo xtask metrics`. `Ok(false)` never: the command reports, it does not judge.
pub fn command(args: &Args) -> Result<bool> {
    let args = *args;
    for axis in Axis::ALL {
        let (_, cfg) = config(axis.index() as u32, args, Closure::Seamless);
        cfg.validate(axis, args.shape.n())
            .map_err(|error| AxisError { axis, error })?;
    }
    println!("$ {}", args.command_line());
    println!(
        "seeds: seed_i = i·2654435761 + 12345 mod 2^32, i = 0..{}; seed i runs on axis i mod 3 \
         (pitch, roll, yaw) with that axis' default range (Table 2): pitch [{}°, {}°], \
         roll [{}°, {}°], yaw [{}°, {}°]; N = {}, W = {}, Mdeg16 storage.",
        args.seeds - 1,
        DEFAULT_HEAD.pitch.range.min.millidegrees() / 1000,
        DEFAULT_HEAD.pitch.range.max.millidegrees() / 1000,
        DEFAULT_HEAD.roll.range.min.millidegrees() / 1000,
        DEFAULT_HEAD.roll.range.max.millidegrees() / 1000,
        DEFAULT_HEAD.yaw.range.min.millidegrees() / 1000,
        DEFAULT_HEAD.yaw.range.max.millidegrees() / 1000,
        args.shape.n(),
        args.shape.w(),
    );
    println!(
        "metrics of the stored loop x, cyclic: d1(n) = x(n+1) − x(n), d2(n) = d1(n+1) − d1(n); \
         P95 and p99 nearest-rank; worst = max for the ratios, min for liveliness and the margins."
    );
    println!();
    let start = Instant::now();
    let mut results = Vec::new();
    for closure in [Closure::Seamless, Closure::Paper] {
        results.push((closure, run(args, closure)?));
    }
    record_figures(&results, args);
    print!("{}", report(&results, args));
    println!(
        "{} loops in {:.1} s",
        2 * u64::from(args.seeds),
        start.elapsed().as_secs_f64()
    );
    Ok(true)
}

/// `cargo xtask metrics`'s distributions, for the measured figures.
fn record_figures(results: &[(Closure, Results)], args: Args) {
    let seeds = figures::thousands(u64::from(args.seeds));
    for (closure, result) in results {
        let name = match closure {
            Closure::Paper => "paper",
            Closure::Seamless => "seamless",
        };
        // The page shows the paper closure's table first: it says what the columns are.
        let columns = if *closure == Closure::Paper {
            format!(
                "One loop per seed, {seeds} seeds, N = {}, W = {}, each seed on one of the \
                 three default axes ([the motion](motion.md#two-loop-closures)); d1 and d2 are \
                 the first and second differences of the loop taken cyclically, seam included; \
                 liveliness is the quietest tenth of the loop's mean speed relative to the \
                 whole loop's; the margins are to the loop's own [α1, α2]. ",
                args.shape.n(),
                args.shape.w()
            )
        } else {
            String::new()
        };
        let intro = format!(
            "{columns}**{name}**: {} of {seeds} loops past a continuity ratio of \
             {CONTINUITY_LIMIT}, {} seeds rejected.",
            result.loops.iter().filter(|m| m.discontinuous()).count(),
            result.rejected.len(),
        );
        let rows = ROWS.iter().map(|(metric, get)| {
            let values = distribution(result.loops.iter().map(get).collect());
            let mut cells = vec![metric.replace('|', "\\|")];
            cells.extend(values.map(|v| format!("{v:.3}")));
            cells
        });
        let header = ["metric", "min", "median", "p99", "max"];
        figures::record(&format!("metrics {name}"), intro, &header, rows.collect());
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact values by construction
mod tests {
    use super::*;

    fn seeds(seeds: u32) -> Args {
        Args {
            seeds,
            shape: LoopShape::default(),
        }
    }

    #[test]
    fn the_command_line_reproduces_the_run() {
        let args = Args {
            seeds: 300,
            shape: LoopShape {
                n: Some(450),
                w: Some(15),
            },
        };
        assert_eq!(
            args.command_line(),
            "cargo xtask metrics --seeds 300 --n 450 --w 15"
        );
        assert_eq!(
            seeds(10_000).command_line(),
            "cargo xtask metrics --seeds 10000 --n 900 --w 59"
        );
    }

    #[test]
    fn seeds_are_spread_and_axes_take_turns() {
        assert_eq!(seed(0), 12_345);
        assert_eq!(seed(1), 2_654_435_761 + 12_345);
        // Wraps modulo 2^32.
        assert_eq!(seed(2), (2 * 2_654_435_761u64 + 12_345) as u32);
        let args = seeds(1);
        let axes: Vec<Axis> = (0..4).map(|i| config(i, args, Closure::Paper).0).collect();
        assert_eq!(axes, [Axis::Pitch, Axis::Roll, Axis::Yaw, Axis::Pitch]);
        let (_, cfg) = config(2, args, Closure::Paper);
        assert_eq!(cfg.range, DEFAULT_HEAD.yaw.range);
        assert_eq!(cfg.closure, Closure::Paper);
    }

    #[test]
    fn nearest_rank_percentiles() {
        let values: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&values, 0.5), 50.0);
        assert_eq!(percentile(&values, 0.99), 99.0);
        assert_eq!(percentile(&values, 1.0), 100.0);
        assert_eq!(percentile(&values, 0.0), 1.0);
        assert_eq!(distribution(vec![3.0, 1.0, 2.0]), [1.0, 2.0, 3.0, 3.0]);
        assert!(percentile(&[], 0.5).is_nan());
    }

    #[test]
    fn a_few_seeds_measure_and_report() {
        let args = seeds(9);
        let results: Vec<(Closure, Results)> = [Closure::Seamless, Closure::Paper]
            .into_iter()
            .map(|closure| (closure, run(args, closure).unwrap()))
            .collect();
        for (closure, result) in &results {
            assert_eq!(result.loops.len() + result.rejected.len(), 9);
            if *closure == Closure::Seamless {
                // The seamless loop starts at the neutral pose and stays in range.
                assert!(result.loops.iter().all(|m| m.start == 0.0));
                assert!(
                    result
                        .loops
                        .iter()
                        .all(|m| m.below >= 0.0 && m.above >= 0.0)
                );
            }
        }
        let text = report(&results, args);
        assert!(text.starts_with("seamless  continuity > 3: "), "{text}");
    }
}
