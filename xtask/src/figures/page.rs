//! The book's page of measured figures, `docs/design/figures.md`, written
//! from the figures on file. Every heading is there whether or not its
//! figures are, so that the other pages' links to it always resolve.

// Sizes and counts are far below 2^52: the float conversions are exact.
#![allow(clippy::cast_precision_loss)]

use std::{fmt::Write as _, path::Path};

use anyhow::{Context, Result};

use super::{Bench, Figures, Latency, Metrics, QemuRun, Source, thousands};

/// The Pico's system clock, for the time a count of instructions takes at
/// least (one cycle each).
const RP2040_MHZ: f64 = 125.0;

/// Writes the page to `page` from the figures in `figures_path`, and
/// returns which sections had figures.
pub fn write_page(figures_path: &Path, page: &Path) -> Result<Vec<&'static str>> {
    let figures = super::load(figures_path)?;
    let (text, recorded) = render(&figures);
    std::fs::write(page, text).with_context(|| format!("writing {}", page.display()))?;
    Ok(recorded)
}

/// The page, and the names of the sections that had figures.
pub fn render(figures: &Figures) -> (String, Vec<&'static str>) {
    let mut out = String::new();
    let mut recorded = Vec::new();
    out.push_str(
        "# Measured figures\n\n\
         <!-- Written by `cargo xtask book` from target/figures.json: not in git, \
         do not edit. -->\n\n\
         These figures are written by the project's tools as they measure, never by \
         hand. `cargo xtask test` records the images' sizes, their RAM with the peak \
         stack, the QEMU run and the benchmark; `cargo xtask bench` the benchmark and \
         the latency rows; `cargo xtask metrics` the loop quality; `cargo xtask book` \
         writes this page from what they recorded \
         (`target/figures.json`). Each section says which command recorded it, and on \
         which commit.\n",
    );
    let mut section = |name: &'static str, title: &str, body: Option<String>, how: &str| {
        let _ = write!(out, "\n## {title}\n\n");
        match body {
            Some(body) => {
                recorded.push(name);
                out.push_str(&body);
            }
            None => {
                let _ = writeln!(out, "Not measured yet: {how}.");
            }
        }
    };
    let test = "`cargo xtask test` measures these (and builds this page again)";
    section("memory", "Memory", memory(figures), test);
    let bench = figures.bench.as_ref();
    let latency = figures.latency.as_ref();
    let frame_cost = (bench.is_some() || latency.is_some()).then(|| {
        format!(
            "{}{}",
            bench.map(frames).unwrap_or_default(),
            latency.map(latency_rows).unwrap_or_default()
        )
    });
    section("frames", "Frame cost", frame_cost, test);
    section("precompute", "Boot precompute", bench.map(precompute), test);
    section(
        "qemu",
        "Idle loop sets",
        figures.qemu.as_ref().map(loop_sets),
        test,
    );
    section(
        "metrics",
        "Loop quality",
        figures.metrics.as_ref().map(metrics),
        "run `cargo xtask metrics`, then `cargo xtask book`",
    );
    (out, recorded)
}

fn recorded_by(source: &Source) -> String {
    match &source.commit {
        Some(commit) => format!("Recorded by `{}` on `{commit}`.\n\n", source.command),
        None => format!("Recorded by `{}`.\n\n", source.command),
    }
}

fn bytes(value: u64) -> String {
    format!("{} B", thousands(value))
}

fn kib(value: u64) -> String {
    format!("{:.1} KiB", value as f64 / 1024.0)
}

fn percent(part: u64, whole: u64) -> String {
    format!("{:.0} %", part as f64 / whole.max(1) as f64 * 100.0)
}

fn memory(figures: &Figures) -> Option<String> {
    if figures.images.is_empty() && figures.ram.is_none() {
        return None;
    }
    let mut out = String::new();
    if !figures.images.is_empty() {
        out.push_str(
            "Flash is every section stored in flash (`.data`'s initial values \
             included); static RAM is `.data + .bss + .uninit`.\n\n\
             | image | flash | of the ceiling | static RAM | recorded by |\n\
             |---|---|---|---|---|\n",
        );
        for (name, image) in &figures.images {
            let ceiling = image.flash_budget.map_or_else(
                || "no ceiling".to_owned(),
                |budget| format!("{} of {}", percent(image.flash, budget), bytes(budget)),
            );
            let _ = writeln!(
                out,
                "| {name} | {} ({}) | {ceiling} | {} | `{}`{} |",
                bytes(image.flash),
                kib(image.flash),
                bytes(image.static_ram),
                image.source.command,
                image
                    .source
                    .commit
                    .as_ref()
                    .map_or_else(String::new, |commit| format!(" on `{commit}`")),
            );
        }
        for (name, image) in &figures.images {
            let sections: Vec<String> = image
                .sections
                .iter()
                .map(|s| format!("`{}` {}", s.name, bytes(s.size)))
                .collect();
            let _ = writeln!(out, "\nSections of `{name}`: {}.", sections.join(", "));
        }
    }
    if let Some(ram) = &figures.ram {
        out.push_str(
            "\nRAM: static RAM plus the deepest the stack went, measured by painting it \
             ([Memory](memory.md#how-the-stack-is-measured)).\n\n",
        );
        out.push_str(&recorded_by(&ram.source));
        out.push_str(
            "| image | stack measured in | static RAM | peak stack | total | of the ceiling |\n\
             |---|---|---|---|---|---|\n",
        );
        for row in &ram.rows {
            let total = row.static_ram + row.stack;
            let ceiling = row.budget.map_or_else(
                || "no ceiling".to_owned(),
                |budget| format!("{} of {}", percent(total, budget), bytes(budget)),
            );
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} ({}) | {ceiling} |",
                row.image,
                row.measured_in,
                bytes(row.static_ram),
                bytes(row.stack),
                bytes(total),
                kib(total),
            );
        }
    }
    Some(out)
}

fn frames(bench: &Bench) -> String {
    let mut out = recorded_by(&bench.source);
    out.push_str(
        "Instructions of one frame update (`FrameLoop::write`: playback, mixer, fade, \
         limits, mapping, three PWM writes) over the frames of a whole loop (the fade-in \
         and a join), counted exactly in QEMU ([what a frame costs](limiter.md#what-a-frame-costs)), \
         at the servo rates 50 Hz (20 ms frames: 2,500,000 cycles of a 125 MHz RP2040) and \
         333 Hz (3003 µs: 375,375 cycles). The CPU load is the mean frame's work over the \
         frame period, an instruction taken as 1 ns (QEMU's time under `-icount shift=0`; a \
         Cortex-M0+ at 125 MHz takes about ten times that).\n\n\
         | row | rate | frames | min | median | max | mean | CPU load | ceiling (median / max) | median at 125 MHz |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for row in &bench.frames {
        let _ = writeln!(
            out,
            "| {} | {} Hz | {} | {} | {} | {} | {} | {} | {} / {} | ≥ {:.1} µs |",
            row.label,
            row.rate.unwrap_or(50),
            thousands(row.frames),
            thousands(row.min),
            thousands(row.median),
            thousands(row.max),
            thousands(row.mean),
            row.load_percent
                .map_or_else(|| "–".to_owned(), |load| format!("{load:.4} %")),
            thousands(row.median_budget),
            thousands(row.max_budget),
            row.median as f64 / RP2040_MHZ,
        );
    }
    out
}

/// The latency rows, under the frame costs.
fn latency_rows(latency: &Latency) -> String {
    if latency.rows.is_empty() {
        return String::new();
    }
    let mut out = String::from(
        "\nLatency, measured in the RP2040 emulator on the shipped image, from an event \
         to the first servo pulse that shows it, in ms \
         ([the emulators](../dev/emulators.md#latency-of-an-input-edge)). ",
    );
    out.push_str(&recorded_by(&latency.source));
    out.push_str(
        "| row | events | p50 | p99 | max | goal (p99) |\n\
         |---|---|---|---|---|---|\n",
    );
    for row in &latency.rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.1} | {:.1} | {:.1} | {:.0}{} |",
            row.label,
            thousands(row.events as u64),
            row.p50_ms,
            row.p99_ms,
            row.max_ms,
            row.goal_p99_ms,
            if row.p99_ms <= row.goal_p99_ms {
                ""
            } else {
                " (missed)"
            },
        );
    }
    out
}

fn precompute(bench: &Bench) -> String {
    let mut out = recorded_by(&bench.source);
    let _ = write!(
        out,
        "Instructions of the three axes' loops, computed at boot, for the default set \
         and across W and N, next to a direct-form f32 implementation of the paper's \
         smoothing on the same core ([how it is computed](motion.md#how-it-is-computed)). \
         The default set's ceiling is {} instructions.\n\n\
         | row | N | W | engine | direct f32 smoothing | ratio | engine at 125 MHz |\n\
         |---|---|---|---|---|---|---|\n",
        thousands(bench.budget)
    );
    for row in &bench.rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {:.0}× | ≥ {:.2} ms |",
            row.label,
            row.n,
            row.w,
            thousands(row.engine),
            thousands(row.direct),
            row.direct as f64 / row.engine.max(1) as f64,
            row.engine as f64 / RP2040_MHZ / 1000.0,
        );
    }
    out
}

fn loop_sets(run: &QemuRun) -> String {
    let mut out = recorded_by(&run.source);
    out.push_str(
        "The QEMU smoke run's loop sets ([never-repeating idle](idle.md#in-the-background)): \
         the boot's set 0, timed before the first frame, and the sets generated in the \
         background while the frames play, each with the loops it discarded per axis \
         (pitch, roll, yaw).\n\n\
         | set | instructions | at 125 MHz | loops discarded |\n|---|---|---|---|\n",
    );
    if let Some(precompute) = run.precompute {
        let _ = writeln!(
            out,
            "| 0 (boot) | {} | ≥ {:.2} ms | none |",
            thousands(precompute),
            precompute as f64 / RP2040_MHZ / 1000.0
        );
    }
    for set in &run.sets {
        let _ = writeln!(
            out,
            "| {} | {} | ≥ {:.2} ms | {} |",
            set.set,
            thousands(set.instructions),
            set.instructions as f64 / RP2040_MHZ / 1000.0,
            set.discarded
        );
    }
    out
}

fn metrics(metrics: &Metrics) -> String {
    let mut out = recorded_by(&metrics.source);
    let _ = writeln!(
        out,
        "One loop per seed and closure, {} seeds, N = {}, W = {}, each seed on one of the \
         three default axes ([the motion](motion.md#two-loop-closures)). d1 and d2 are the \
         first and second differences of the loop taken cyclically, seam included; \
         liveliness is the quietest tenth of the loop's mean speed relative to the whole \
         loop's; the margins are to the loop's own [α1, α2].",
        thousands(u64::from(metrics.seeds)),
        metrics.n,
        metrics.w
    );
    for closure in &metrics.closures {
        let _ = write!(
            out,
            "\n**{}**: {} of {} loops past a continuity ratio of {}, {} seeds rejected.\n\n\
             | metric | min | median | p99 | max |\n|---|---|---|---|---|\n",
            closure.closure,
            closure.discontinuous,
            thousands(u64::from(metrics.seeds)),
            metrics.limit,
            closure.rejected,
        );
        for row in &closure.rows {
            let [min, median, p99, max] = row.values;
            let _ = writeln!(
                out,
                "| {} | {min:.3} | {median:.3} | {p99:.3} | {max:.3} |",
                row.metric.replace('|', "\\|")
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::{FrameCost, Image, LatencyRow, PrecomputeRow, Section};
    use super::*;

    fn source() -> Source {
        Source {
            command: "cargo xtask test".into(),
            commit: Some("abc1234".into()),
        }
    }

    fn input_edge() -> Latency {
        Latency {
            source: source(),
            rows: vec![LatencyRow {
                label: "latency input edge".into(),
                events: 1000,
                p50_ms: 45.6,
                p99_ms: 55.0,
                max_ms: 55.1,
                goal_p99_ms: 25.0,
            }],
        }
    }

    #[test]
    fn an_empty_record_says_how_to_measure_under_every_heading() {
        let (page, recorded) = render(&Figures::default());
        assert!(recorded.is_empty());
        for heading in [
            "## Memory",
            "## Frame cost",
            "## Boot precompute",
            "## Idle loop sets",
            "## Loop quality",
        ] {
            assert!(page.contains(heading), "{heading}");
        }
        assert_eq!(page.matches("Not measured yet").count(), 5);
        assert!(page.contains("run `cargo xtask metrics`, then `cargo xtask book`"));
        assert!(page.contains("`cargo xtask test` measures these"));
    }

    #[test]
    fn recorded_figures_are_shown_with_their_source() {
        let mut figures = Figures::default();
        figures.images.insert(
            "pico".into(),
            Image {
                source: source(),
                flash: 101_200,
                flash_budget: Some(131_072),
                static_ram: 20_764,
                sections: vec![Section {
                    name: ".text".into(),
                    size: 90_000,
                    stored: true,
                }],
            },
        );
        figures.bench = Some(Bench {
            source: source(),
            budget: 150_000,
            rows: vec![PrecomputeRow {
                label: "default".into(),
                n: 900,
                w: 59,
                engine: 148_960,
                direct: 37_010_000,
            }],
            frames: vec![FrameCost {
                label: "frame (gesture + look)".into(),
                rate: Some(50),
                load_percent: Some(0.0074),
                frames: 1601,
                min: 1292,
                median: 1433,
                max: 1880,
                mean: 1476,
                median_budget: 1000,
                max_budget: 2000,
            }],
        });
        figures.latency = Some(input_edge());
        let (page, recorded) = render(&figures);
        assert!(page.contains("| latency input edge | 1,000 | 45.6 | 55.0 | 55.1 | 25 (missed) |"));
        assert_eq!(recorded, ["memory", "frames", "precompute"]);
        assert!(page.contains("| pico | 101,200 B (98.8 KiB) | 77 % of 131,072 B | 20,764 B |"));
        assert!(page.contains("Recorded by `cargo xtask test` on `abc1234`."));
        assert!(page.contains("| default | 900 | 59 | 148,960 | 37,010,000 | 248× |"));
        assert!(page.contains("| 1,000 / 2,000 | ≥ 11.5 µs |"));
        assert_eq!(page.matches("Not measured yet").count(), 2);
    }

    #[test]
    fn latency_rows_are_shown_without_a_benchmark() {
        let figures = Figures {
            latency: Some(input_edge()),
            ..Figures::default()
        };
        let (page, recorded) = render(&figures);
        assert_eq!(recorded, ["frames"]);
        assert!(page.contains("| latency input edge | 1,000 | 45.6 | 55.0 | 55.1 | 25 (missed) |"));
        assert!(page.contains("Recorded by `cargo xtask test` on `abc1234`."));
        assert!(!page.contains("| row | frames |"));
    }
}
