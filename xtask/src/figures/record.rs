//! What each measuring function records: one call each, from the figures
//! it has already computed.

use std::path::Path;

use idle_head_core::motion::Closure;

use super::{
    Bench, ClosureMetrics, FrameCost, Image, MetricRow, Metrics, PrecomputeRow, QemuRun, Ram,
    RamRow, Section, SetCost, Source, save_section,
};
use crate::{
    bench::{FrameRow, Row},
    elf::{self, Peak},
    log::LogLine,
    metrics::{self, Results},
    qemu::Summary,
};

/// The sizes of the image at `path`, held to `flash_budget`.
pub fn image(path: &Path, image: &elf::Image, flash_budget: Option<u64>) {
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let entry = Image {
        source: Source::now(),
        flash: image.flash(),
        flash_budget,
        static_ram: image.static_ram(),
        sections: image
            .sections
            .iter()
            .map(|s| Section {
                name: s.name.clone(),
                size: s.size,
                stored: s.stored,
            })
            .collect(),
    };
    save_section(&format!("sizes of `{name}`"), |f| {
        f.images.insert(name.clone(), entry);
    });
}

/// Static RAM plus the peak stack of each image that has a measurement:
/// `(image, where the stack was measured, the peak, the ceiling)`.
pub fn ram(rows: &[(&str, &str, Option<Peak>, Option<u64>)]) {
    let rows: Vec<RamRow> = rows
        .iter()
        .filter_map(|&(image, measured_in, peak, budget)| {
            peak.map(|peak| RamRow {
                image: image.to_owned(),
                measured_in: measured_in.to_owned(),
                static_ram: peak.static_ram,
                stack: peak.stack,
                budget,
            })
        })
        .collect();
    if rows.is_empty() {
        return;
    }
    let source = Source::now();
    save_section("RAM with the peak stack", |f| {
        f.ram = Some(Ram { source, rows });
    });
}

/// The benchmark's rows.
pub fn bench(rows: &[Row], frames: &[FrameRow], budget: u64) {
    let entry = Bench {
        source: Source::now(),
        budget,
        rows: rows
            .iter()
            .map(|row| PrecomputeRow {
                label: row.label.clone(),
                n: row.n,
                w: row.w,
                engine: row.engine,
                direct: row.direct,
            })
            .collect(),
        frames: frames
            .iter()
            .map(|row| FrameCost {
                label: row.label(),
                frames: row.frames,
                min: row.min,
                median: row.median,
                max: row.max,
                mean: row.mean,
                median_budget: row.ceiling().map_or(0, |c| c.median),
                max_budget: row.ceiling().map_or(0, |c| c.max),
                // Every row with a ceiling is held to it.
                held: row.ceiling().is_some(),
            })
            .collect(),
    };
    save_section("benchmark", |f| f.bench = Some(entry));
}

/// The QEMU smoke run's boot precompute (`precompute_insns` of its summary
/// line) and the loop sets its log reports. Only the smoke run's: a run
/// with console traffic would count that traffic in its sets' times.
pub fn qemu(log: &[LogLine]) {
    let entry = QemuRun {
        source: Source::now(),
        precompute: Summary::find(log).and_then(|s| s.number("precompute_insns").ok()),
        sets: log
            .iter()
            .filter_map(|line| set_cost(&line.message))
            .collect(),
    };
    save_section("QEMU run", |f| f.qemu = Some(entry));
}

/// `loop set <n> ready in <insns> instructions: seeds [..] ([..] discarded), ...`
fn set_cost(message: &str) -> Option<SetCost> {
    let rest = message.strip_prefix("loop set ")?;
    let (set, rest) = rest.split_once(" ready in ")?;
    let (instructions, rest) = rest.split_once(" instructions")?;
    let discarded = rest
        .split_once('(')
        .and_then(|(_, after)| after.split_once(" discarded)"))
        .map_or_else(String::new, |(list, _)| list.to_owned());
    Some(SetCost {
        set: set.parse().ok()?,
        instructions: instructions.parse().ok()?,
        discarded,
    })
}

/// `cargo xtask metrics`'s distributions.
pub fn loop_quality(results: &[(Closure, Results)], args: metrics::Args) {
    let closures = results
        .iter()
        .map(|(closure, result)| ClosureMetrics {
            closure: match closure {
                Closure::Paper => "paper",
                Closure::Seamless => "seamless",
            }
            .to_owned(),
            rows: metrics::ROWS
                .iter()
                .map(|(metric, get)| MetricRow {
                    metric: (*metric).to_owned(),
                    values: metrics::distribution(result.loops.iter().map(get).collect()),
                })
                .collect(),
            discontinuous: result.loops.iter().filter(|m| m.discontinuous()).count(),
            rejected: result.rejected.len(),
        })
        .collect();
    let entry = Metrics {
        source: Source::now(),
        seeds: args.seeds,
        n: args.shape.n(),
        w: args.shape.w(),
        limit: metrics::CONTINUITY_LIMIT,
        closures,
    };
    save_section("loop quality", |f| f.metrics = Some(entry));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_loop_set_lines() {
        let set = set_cost(
            "loop set 2 ready in 3470000 instructions: seeds [0x417b904f, 0xcbb40bbb, \
             0xd00c5039] ([2, 3, 3] discarded), entered at [407, 233, 791], join mismatch \
             [1142, 1108, 1391] mdeg rms",
        )
        .unwrap();
        assert_eq!(
            (set.set, set.instructions, set.discarded.as_str()),
            (2, 3_470_000, "[2, 3, 3]")
        );
        assert!(set_cost("loop set failed: range; trying the next seeds").is_none());
        assert!(set_cost("frame 1400: join").is_none());
    }
}
