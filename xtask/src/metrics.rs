//! `cargo xtask metrics`: the loop metrics ([`LoopMetrics`]) over many
//! seeds, both closures; ranges relative to the loop's own [α1, α2],
//! percentiles nearest-rank.

// Counts and angles are small: float conversions are exact or harmless.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]

use std::{thread, time::Instant};

use anyhow::{Context, Result, anyhow};
use idle_head_core::{
    Axis,
    metrics::LoopMetrics,
    motion::{AxisConfig, AxisError, Closure, DEFAULT_HEAD, HannKernel, Mdeg16, generate_into},
};

use crate::args::LoopShape;
use crate::figures;
use crate::preview::{closure_name, deg};

/// The continuity ratio a loop must not exceed (max over P95, both d1 and d2).
pub const CONTINUITY_LIMIT: f64 = 3.0;

/// Options of `cargo xtask metrics` (its help text is in `cli.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::Args)]
pub struct Args {
    /// Seeds per closure.
    #[arg(long, value_name = "count", allow_negative_numbers = true, default_value_t = 10_000,
          value_parser = crate::args::at_least_one::<u32>)]
    pub seeds: u32,
    #[command(flatten)]
    pub shape: LoopShape,
}

/// The configuration of seed number `i`: axis i mod 3 with its default
/// row, seed `i · 2654435761 + 12345` mod 2³² (spread over the `u32` range).
pub fn config(i: u32, args: Args, closure: Closure) -> (Axis, AxisConfig) {
    let axis = Axis::ALL[(i % 3) as usize];
    let seed = i.wrapping_mul(2_654_435_761).wrapping_add(12_345);
    let cfg = DEFAULT_HEAD.axis(axis).with_seed(seed);
    (axis, cfg.with_window(args.shape.w()).with_closure(closure))
}

/// What is measured of a loop of a configuration.
type Measure = fn(&LoopMetrics, &AxisConfig) -> f64;

/// The table rows: name, and the value measured for one loop: its
/// continuity ratios, liveliness, margins to its range (°) and start (°).
const ROWS: [(&str, Measure); 6] = [
    ("max|d1|/P95|d1|", |m, _| f64::from(m.velocity_ratio)),
    ("max|d2|/P95|d2|", |m, _| f64::from(m.acceleration_ratio)),
    ("liveliness", |m, _| f64::from(m.liveliness)),
    ("min − α1 (°)", |m, c| deg(m.min) - deg(c.range.min)),
    ("α2 − max (°)", |m, c| deg(c.range.max) - deg(m.max)),
    ("start x(0) (°)", |m, _| deg(m.start)),
];

/// Nearest-rank percentile `q` (0..=1) of sorted values.
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len().max(1));
    sorted.get(rank - 1).copied().unwrap_or(f64::NAN)
}

/// Per measured seed, the [`ROWS`]' values; the seeds the engine rejected
/// (for example a flat walk), with the reason.
#[derive(Debug, Default)]
pub struct Results {
    pub loops: Vec<[f64; 6]>,
    pub rejected: Vec<(u32, String)>,
}

impl Results {
    fn count(&self, past: impl Fn(&[f64; 6]) -> bool) -> usize {
        self.loops.iter().filter(|m| past(m)).count()
    }

    /// Loops past the continuity limit on either ratio.
    fn discontinuous(&self) -> usize {
        self.count(|m| m[0] > CONTINUITY_LIMIT || m[1] > CONTINUITY_LIMIT)
    }
}

fn measure(range: std::ops::Range<u32>, args: Args, closure: Closure) -> Result<Results> {
    let kernel = HannKernel::new(args.shape.w())?;
    let (mut buffer, mut scratch) = (vec![Mdeg16(0); args.shape.n()], vec![0; args.shape.n()]);
    let mut results = Results::default();
    for i in range {
        let (axis, cfg) = config(i, args, closure);
        match generate_into(&mut buffer, &cfg, axis, &kernel, &mut ()) {
            Ok(_) => {
                let metrics = LoopMetrics::measure(&buffer, &mut scratch)
                    .context("the loop is too short to measure")?;
                results.loops.push(ROWS.map(|(_, get)| get(&metrics, &cfg)));
            }
            Err(error) => results.rejected.push((cfg.seed, error.to_string())),
        }
    }
    Ok(results)
}

/// `job` of 0 to `count` − 1, `cores` at a time, in order; a job that
/// panicked is an error.
pub fn parallel<T: Send>(
    count: usize,
    cores: usize,
    job: impl Fn(usize) -> Result<T> + Sync,
) -> Vec<Result<T>> {
    let mut results = Vec::new();
    for batch in (0..count).collect::<Vec<_>>().chunks(cores.max(1)) {
        thread::scope(|scope| {
            let job = &job;
            let runs: Vec<_> = batch.iter().map(|&i| scope.spawn(move || job(i))).collect();
            let panicked = || Err(anyhow!("a worker thread panicked"));
            results.extend(
                runs.into_iter()
                    .map(|run| run.join().unwrap_or_else(|_| panicked())),
            );
        });
    }
    results
}

/// Measures every seed for `closure` on all available cores.
pub fn run(args: Args, closure: Closure) -> Result<Results> {
    let threads = thread::available_parallelism().map_or(1, usize::from) as u32;
    let chunk = args.seeds.div_ceil(threads);
    let part = |t: usize| {
        let [from, to] = [t, t + 1].map(|t| (t as u32 * chunk).min(args.seeds));
        measure(from..to, args, closure)
    };
    let mut all = Results::default();
    for part in parallel(threads as usize, threads as usize, part) {
        let part = part?;
        all.loops.extend(part.loops);
        all.rejected.extend(part.rejected);
    }
    Ok(all)
}

/// `cargo xtask metrics`. `Ok(false)` never: the command reports, it does not judge.
pub fn command(args: &Args) -> Result<bool> {
    let args = *args;
    let (seeds, n, w) = (args.seeds, args.shape.n(), args.shape.w());
    for axis in Axis::ALL {
        let (_, cfg) = config(axis.index() as u32, args, Closure::Seamless);
        cfg.validate(axis, n)
            .map_err(|error| AxisError { axis, error })?;
    }
    println!("$ cargo xtask metrics --seeds {seeds} --n {n} --w {w}");
    let range = |axis: Axis| {
        let r = DEFAULT_HEAD.axis(axis).range;
        format!("{} [{}°, {}°]", axis.name(), deg(r.min), deg(r.max))
    };
    println!(
        "seeds: seed_i = i·2654435761 + 12345 mod 2^32, i = 0..{}; seed i runs on axis i mod 3 \
         with that axis' default range (Table 2): {}; N = {n}, W = {w}, Mdeg16 storage.",
        seeds - 1,
        Axis::ALL.map(range).join(", ")
    );
    println!(
        "metrics of the stored loop x, cyclic: d1(n) = x(n+1) − x(n), d2(n) = d1(n+1) − d1(n); \
         P95 and p99 nearest-rank; worst = max for the ratios, min for liveliness and the \
         margins.\n"
    );
    let start = Instant::now();
    for closure in [Closure::Seamless, Closure::Paper] {
        let result = run(args, closure)?;
        let name = closure_name(closure);
        println!(
            "{name:<9} continuity > {CONTINUITY_LIMIT}: {} of {seeds} seeds (velocity {}, \
             acceleration {}); outside [α1, α2]: {}; start ≠ 0: {}; rejected: {}",
            result.discontinuous(),
            result.count(|m| m[0] > CONTINUITY_LIMIT),
            result.count(|m| m[1] > CONTINUITY_LIMIT),
            result.count(|m| m[3] < 0.0 || m[4] < 0.0),
            result.count(|m| m[5] != 0.0),
            result.rejected.len(),
        );
        for (seed, reason) in result.rejected.iter().take(3) {
            println!("          rejected seed {seed}: {reason}");
        }
        record_figures(closure, &result, args);
    }
    let seconds = start.elapsed().as_secs_f64();
    println!("{} loops in {seconds:.1} s", 2 * u64::from(seeds));
    Ok(true)
}

/// A closure's distributions (min, median, p99, max), for the figures.
fn record_figures(closure: Closure, result: &Results, args: Args) {
    let seeds = figures::thousands(u64::from(args.seeds));
    let name = closure_name(closure);
    // The page shows the paper closure's table first: it says what the columns are.
    let columns = if closure == Closure::Paper {
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
        "{columns}**{name}**: {} of {seeds} loops past a continuity ratio of {CONTINUITY_LIMIT}, \
         {} seeds rejected.",
        result.discontinuous(),
        result.rejected.len(),
    );
    let rows = ROWS.iter().enumerate().map(|(i, (metric, _))| {
        let mut values: Vec<f64> = result.loops.iter().map(|m| m[i]).collect();
        values.sort_by(f64::total_cmp);
        let mut cells = vec![metric.replace('|', "\\|")];
        cells.extend([0.0, 0.5, 0.99, 1.0].map(|q| format!("{:.3}", percentile(&values, q))));
        cells
    });
    let header = ["metric", "min", "median", "p99", "max"];
    figures::record(&format!("metrics {name}"), intro, &header, rows.collect());
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact values by construction
mod tests {
    use super::*;

    #[test]
    fn seeds_percentiles_and_a_few_loops() {
        let args = Args {
            seeds: 9,
            shape: LoopShape::default(),
        };
        let axes: Vec<Axis> = (0..4).map(|i| config(i, args, Closure::Paper).0).collect();
        assert_eq!(axes, [Axis::Pitch, Axis::Roll, Axis::Yaw, Axis::Pitch]);
        let (_, cfg) = config(2, args, Closure::Paper);
        // Seeds wrap modulo 2^32.
        assert_eq!(cfg.seed, (2 * 2_654_435_761_u64 + 12_345) as u32);
        assert_eq!(
            (cfg.range, cfg.closure),
            (DEFAULT_HEAD.yaw.range, Closure::Paper)
        );
        let values: Vec<f64> = (1..=100).map(f64::from).collect();
        let ranks = [0.0, 0.5, 0.99, 1.0].map(|q| percentile(&values, q));
        assert_eq!(ranks, [1.0, 50.0, 99.0, 100.0]);
        assert!(percentile(&[], 0.5).is_nan());
        for closure in [Closure::Seamless, Closure::Paper] {
            let result = run(args, closure).unwrap();
            assert_eq!(result.loops.len() + result.rejected.len(), 9);
            if closure == Closure::Seamless {
                // The seamless loop starts at the neutral pose and stays in range.
                let mut loops = result.loops.iter();
                assert!(loops.all(|m| m[5] == 0.0 && m[3] >= 0.0 && m[4] >= 0.0));
            }
        }
    }
}
