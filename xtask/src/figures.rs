//! Measured figures: what the commands measure, kept in
//! `target/figures.json`, and the book's page made from them.
//!
//! The figures in the docs (memory, frame cost, loop quality) are never
//! typed by hand. The functions that measure them record them here as they
//! go, one section each, over whatever the file held:
//!
//! | section | recorded by | run by |
//! |---|---|---|
//! | `images` | [`elf::check_pico`](crate::elf::check_pico) → [`elf::record_image`](crate::elf::record_image) | `cargo xtask test` |
//! | `ram` | [`elf::check_ram`](crate::elf::check_ram) → [`elf::record_ram`](crate::elf::record_ram) | `cargo xtask test` |
//! | `qemu` | [`qemu::check_summary`](crate::qemu::check_summary) → [`qemu::record_figures`](crate::qemu::record_figures) | `cargo xtask qemu`, `cargo xtask test` |
//! | `bench` | [`bench::run_and_check`](crate::bench::run_and_check) → its `record_figures` | `cargo xtask bench`, `cargo xtask test` |
//! | `latency` | [`bench::command`](crate::bench::command) → its `record_latency` | `cargo xtask bench` |
//! | `metrics` | [`metrics::command`](crate::metrics::command) → its `record_figures` | `cargo xtask metrics` |
//!
//! `cargo xtask book` then writes `docs/design/figures.md` (ignored by git)
//! with [`write_page`] before it builds the book. Each section says which
//! command recorded it, on which commit; a section never recorded says how
//! to get it.

mod page;

use std::{
    collections::BTreeMap,
    path::{Path, PathBuf},
    process::Command,
};

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

pub use page::write_page;

use crate::project;

/// Everything recorded so far. Sections are replaced whole by the command
/// that measures them; the others stay as they were.
#[derive(Debug, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Figures {
    /// Flash and static RAM of each firmware image, by ELF name.
    pub images: BTreeMap<String, Image>,
    /// Static RAM plus the measured peak stack.
    pub ram: Option<Ram>,
    /// The QEMU smoke run: the boot precompute and the loop sets.
    pub qemu: Option<QemuRun>,
    /// The benchmark: boot precompute rows and frame cost rows.
    pub bench: Option<Bench>,
    /// The latency rows, measured in the RP2040 emulator.
    pub latency: Option<Latency>,
    /// Loop quality over many seeds.
    pub metrics: Option<Metrics>,
}

/// Which command recorded a section, on which commit.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Source {
    /// The command line, as typed (`cargo xtask test`).
    pub command: String,
    /// `git describe --always --dirty` of the working tree, if git answered.
    pub commit: Option<String>,
}

impl Source {
    /// The running command and the working tree's commit.
    pub fn now() -> Self {
        let args: Vec<String> = std::env::args().skip(1).collect();
        let commit = Command::new("git")
            .args(["describe", "--always", "--dirty"])
            .current_dir(project::root())
            .output()
            .ok()
            .filter(|out| out.status.success())
            .and_then(|out| String::from_utf8(out.stdout).ok())
            .map(|text| text.trim().to_owned())
            .filter(|text| !text.is_empty());
        Self {
            command: format!("cargo xtask {}", args.join(" ")).trim().to_owned(),
            commit,
        }
    }
}

/// One allocated section of an image.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Section {
    /// `.text`, `.bss`, ...
    pub name: String,
    /// Bytes.
    pub size: u64,
    /// Whether it is stored in flash.
    pub stored: bool,
}

/// A firmware image's sizes.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Image {
    /// Who recorded it.
    pub source: Source,
    /// Bytes stored in flash.
    pub flash: u64,
    /// The flash ceiling, if the image is held to one.
    pub flash_budget: Option<u64>,
    /// `.data + .bss + .uninit`.
    pub static_ram: u64,
    /// The allocated sections.
    pub sections: Vec<Section>,
}

/// One image's RAM with its measured peak stack.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RamRow {
    /// The image.
    pub image: String,
    /// Where the stack was measured.
    pub measured_in: String,
    /// `.data + .bss + .uninit`.
    pub static_ram: u64,
    /// Deepest stack use, bytes.
    pub stack: u64,
    /// The ceiling of static RAM plus the peak stack, if held to one.
    pub budget: Option<u64>,
}

/// Static RAM plus peak stack, per image.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Ram {
    /// Who recorded it.
    pub source: Source,
    /// One row per image measured.
    pub rows: Vec<RamRow>,
}

/// One loop set generated in the background during the QEMU run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SetCost {
    /// The set's number (1 is the first after the boot's).
    pub set: u64,
    /// Instructions it took.
    pub instructions: u64,
    /// Loops discarded per axis, as logged (`[0, 1, 0]`).
    pub discarded: String,
}

/// What the QEMU smoke run measured.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct QemuRun {
    /// Who recorded it.
    pub source: Source,
    /// Instructions of the boot's first loop set.
    pub precompute: Option<u64>,
    /// The loop sets generated in the background.
    pub sets: Vec<SetCost>,
}

/// A boot precompute row of the benchmark.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PrecomputeRow {
    /// `default`, `w15`, ...
    pub label: String,
    /// Samples per loop.
    pub n: u64,
    /// Hann window taps.
    pub w: u64,
    /// Instructions of the engine, three axes.
    pub engine: u64,
    /// Instructions of the direct-form f32 smoothing, three axes.
    pub direct: u64,
}

/// A frame cost row of the benchmark.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FrameCost {
    /// `frame`, `frame (gesture + look)`, `frame at 333 Hz`.
    pub label: String,
    /// The servo rate it was measured at, Hz (absent in older figures: 50).
    #[serde(default)]
    pub rate: Option<u32>,
    /// The CPU load of the mean frame at that rate, % (1 ns an
    /// instruction).
    #[serde(default)]
    pub load_percent: Option<f64>,
    /// Frames measured.
    pub frames: u64,
    /// Fewest instructions.
    pub min: u64,
    /// Median.
    pub median: u64,
    /// Most instructions.
    pub max: u64,
    /// Mean.
    pub mean: u64,
    /// Ceiling of the median.
    pub median_budget: u64,
    /// Ceiling of the max.
    pub max_budget: u64,
}

/// The benchmark's figures.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Bench {
    /// Who recorded it.
    pub source: Source,
    /// Ceiling of the default set's precompute, instructions.
    pub budget: u64,
    /// The precompute rows, in table order.
    pub rows: Vec<PrecomputeRow>,
    /// The frame rows.
    pub frames: Vec<FrameCost>,
}

/// A latency row: from an event to the first pulse that shows it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LatencyRow {
    /// `latency input edge`, ...
    pub label: String,
    /// Events measured.
    pub events: usize,
    /// Median, 99th percentile and largest, ms.
    pub p50_ms: f64,
    /// See `p50_ms`.
    pub p99_ms: f64,
    /// See `p50_ms`.
    pub max_ms: f64,
    /// The goal for the 99th percentile, ms.
    pub goal_p99_ms: f64,
}

/// The latency rows, measured in the RP2040 emulator.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Latency {
    /// Who recorded them.
    pub source: Source,
    /// One row per path (DMX, a look over USB, an input edge).
    pub rows: Vec<LatencyRow>,
}

/// One metric's distribution over the seeds.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MetricRow {
    /// The metric's name.
    pub metric: String,
    /// min, median, p99, max.
    pub values: [f64; 4],
}

/// One closure's loop quality.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ClosureMetrics {
    /// `seamless` or `paper`.
    pub closure: String,
    /// The distributions.
    pub rows: Vec<MetricRow>,
    /// Loops past the continuity limit.
    pub discontinuous: usize,
    /// Seeds the engine rejected.
    pub rejected: usize,
}

/// `cargo xtask metrics`'s figures.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Metrics {
    /// Who recorded it.
    pub source: Source,
    /// Seeds per closure.
    pub seeds: u32,
    /// Samples per loop.
    pub n: usize,
    /// Window taps.
    pub w: u16,
    /// The continuity limit the counts are against.
    pub limit: f32,
    /// Per closure.
    pub closures: Vec<ClosureMetrics>,
}

/// `1234567` as `1,234,567`.
pub fn thousands(value: u64) -> String {
    let digits = value.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Where the figures are kept: `target/figures.json` at the repository's
/// root, beside the book (`target/book`).
pub fn path() -> PathBuf {
    project::root().join("target").join("figures.json")
}

/// Reads the figures at `path`; none recorded yet if there is no file. A
/// file that cannot be read as figures is an error naming it.
pub fn load(path: &Path) -> Result<Figures> {
    match std::fs::read_to_string(path) {
        Ok(text) => serde_json::from_str(&text)
            .with_context(|| format!("{} holds no figures this xtask can read", path.display())),
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => Ok(Figures::default()),
        Err(error) => Err(error).with_context(|| format!("reading {}", path.display())),
    }
}

/// Applies `change` to the figures on file and writes them back (through a
/// temporary file, so a reader never sees half a file). A file this xtask
/// cannot read (written by another version of it) is started afresh.
fn update_at(path: &Path, change: impl FnOnce(&mut Figures)) -> Result<()> {
    let mut figures = load(path).unwrap_or_else(|error| {
        println!("figures: {error:#}; starting afresh");
        Figures::default()
    });
    change(&mut figures);
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let partial = path.with_extension("json.partial");
    let text = serde_json::to_string_pretty(&figures)?;
    std::fs::write(&partial, text).with_context(|| format!("writing {}", partial.display()))?;
    std::fs::rename(&partial, path).with_context(|| format!("writing {}", path.display()))
}

/// Records a section in [`path`]. A figure that cannot be recorded does not
/// fail the check that measured it: it is reported, and the book's page
/// then shows the last figures recorded.
pub fn save_section(what: &str, change: impl FnOnce(&mut Figures)) {
    let path = path();
    match update_at(&path, change) {
        Ok(()) => println!(
            "  ({what} recorded in {})",
            project::relative(&path).display()
        ),
        Err(error) => println!("warning: {what} not recorded: {error:#}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(flash: u64) -> Image {
        Image {
            source: Source::default(),
            flash,
            flash_budget: Some(131_072),
            static_ram: 20_000,
            sections: vec![Section {
                name: ".text".into(),
                size: flash,
                stored: true,
            }],
        }
    }

    #[test]
    fn thousands_separators() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(133_967_040), "133,967,040");
    }

    #[test]
    fn a_file_from_before_the_latency_section_still_loads() {
        // The latency rows inside `bench`, a `held` on each frame row.
        let old = r#"{"bench": {"source": {"command": "cargo xtask bench", "commit": null},
            "budget": 150000, "rows": [],
            "frames": [{"label": "frame", "frames": 1601, "min": 1, "median": 2, "max": 3,
                "mean": 2, "median_budget": 1000, "max_budget": 2000, "held": true}],
            "latency": [{"label": "latency dmx", "events": 1, "p50_ms": 1.0, "p99_ms": 1.0,
                "max_ms": 1.0, "goal_p99_ms": 25.0}]}}"#;
        let figures: Figures = serde_json::from_str(old).unwrap();
        assert_eq!(figures.bench.unwrap().frames[0].max_budget, 2000);
        assert!(figures.latency.is_none());
    }

    #[test]
    fn sections_are_replaced_and_the_others_kept() {
        let dir = std::env::temp_dir().join(format!("figures-test-{}", std::process::id()));
        let path = dir.join("figures.json");
        let _ = std::fs::remove_dir_all(&dir);
        assert!(load(&path).unwrap().images.is_empty());
        update_at(&path, |f| {
            f.images.insert("pico".into(), image(100));
        })
        .unwrap();
        update_at(&path, |f| {
            f.qemu = Some(QemuRun {
                source: Source::default(),
                precompute: Some(7),
                sets: Vec::new(),
            });
        })
        .unwrap();
        update_at(&path, |f| {
            f.images.insert("pico".into(), image(200));
        })
        .unwrap();
        let figures = load(&path).unwrap();
        assert_eq!(figures.images["pico"].flash, 200);
        assert_eq!(figures.qemu.unwrap().precompute, Some(7));
        // A file of another shape is started afresh, not kept half-read.
        std::fs::write(&path, "{\"images\": 3}").unwrap();
        assert!(load(&path).is_err());
        update_at(&path, |f| {
            f.images.insert("pico".into(), image(300));
        })
        .unwrap();
        let figures = load(&path).unwrap();
        assert_eq!(figures.images["pico"].flash, 300);
        assert!(figures.qemu.is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
