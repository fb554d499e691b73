//! `cargo xtask preview`: the stages of a loop as CSV and PNG, for people.
//!
//! For one axis configuration this runs the core library's engine on the host
//! (`generate_into` with a [`Trace`] observer) and writes
//!
//! - `<out>/<stem>.csv` with the header `n,walk,smoothed,normalized,final`,
//!   every value in degrees, one row per sample index n = 0..N−1;
//! - `<out>/<stem>.png`, stacked panels in the style of the paper's Figures 6
//!   and 7, and a text box with the loop's metrics.
//!
//! The columns:
//!
//! - `walk`: the random walk, δ = the configuration's step. Paper closure:
//!   u(0) = 0, u(n) = u(n−1) ± δ with the sign from r(n) (the LCG value after
//!   n draws). Seamless closure: the circular walk with e(k) = ±1 from r(k+1),
//!   k = 0..N−1, detrended: walk(n) = δ·Σ_{k≤n} (e(k) − D/N), D = Σ e.
//! - `smoothed`: the engine's smoothed walk ([`Trace::smoothed`]) in degrees,
//!   shifted by a constant so that its mean is the walk's mean (the engine
//!   defines it only up to an additive constant).
//! - `normalized`: the paper's normalisation of `smoothed` into [α1, α2]:
//!   α1 + (s − `s_min`)·(α2 − α1)/(`s_max` − `s_min`).
//! - `final`: the stored loop (`Mdeg16`) in degrees, in playback order
//!   (index 0 is where playback starts).
//!
//! The first three are in generation order, `final` in playback order: the
//! engine starts the loop at the split point p = [`LoopInfo::split`], so
//! `final(i)` is the closure's last stage at generation index (i + p) mod N.
//! The paper closure's last stage is the normalised loop times the length-N
//! Hann taper ½ − ½·cos(2πn/(N−1)); its PNG shows the taper and the tapered
//! loop too. The seamless closure scales the smoothed loop about its crossing
//! of the neutral level instead of min-max, so its `final` is the normalised
//! loop rotated and rescaled (the tighter side of the range is reached).

// Sample indices (< 2^13) and angles are small: float conversions are exact
// or far below the plot's resolution.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss,
    clippy::cast_possible_wrap
)]

use std::{
    fmt::Write as _,
    fs,
    path::{Path, PathBuf},
    sync::Once,
};

use anyhow::{Context, Result, anyhow, bail};
use idle_head::{
    Angle, AngleRange, Axis,
    metrics::LoopMetrics,
    motion::{
        AxisConfig, Closure, DEFAULT_HEAD, DEFAULT_N, FINE_PER_MDEG, HannKernel, Lcg, LoopInfo,
        Mdeg16, Trace, generate_into, step_of,
    },
};
use plotters::{
    coord::Shift,
    prelude::*,
    style::{
        FontStyle, register_font,
        text_anchor::{HPos, Pos, VPos},
    },
};

use crate::args;

/// `cargo xtask preview -h`.
pub const HELP: &str = "\
Usage: cargo xtask preview [options]

Writes <out>/<stem>.csv (header n,walk,smoothed,normalized,final; degrees)
and <out>/<stem>.png (the stages as stacked panels, the split point marked,
the loop's metrics) and prints the metrics. With none of the loop options
(--axis, --seed, --n, --w, --range, --closure) it previews the three default
axes (paper, Table 2; N = 900) as <out>/pitch.*, roll.*, yaw.*.

Options:
  --axis <pitch|roll|yaw>     Axis whose default row fills in the loop options
                              not given, and whose anatomical limits the range
                              must respect (default yaw).
  --seed <u32>                LCG seed r(0).
  --n <N>                     Samples per loop (default 900).
  --w <W>                     Hann window taps.
  --range <a1> <a2>           Target range [α1, α2] in degrees (decimals allowed).
  --closure <paper|seamless>  Loop closure (default seamless).
  --out <dir>                 Output directory (default `preview`).
  --name <stem>               File stem (default `loop`; for the default axes
                              <stem>-<axis>).
  -h, --help                  Show this text.

The README's picture: cargo xtask preview --axis yaw --out docs --name preview-yaw
";

/// Options of `cargo xtask preview`.
#[derive(Debug, Clone, PartialEq)]
pub struct Args {
    /// Axis whose default row fills in the missing options (and whose
    /// anatomical limits the range must respect).
    pub axis: Option<Axis>,
    /// LCG seed r(0).
    pub seed: Option<u32>,
    /// Samples per loop.
    pub n: Option<usize>,
    /// Hann window taps.
    pub w: Option<u16>,
    /// [α1, α2] in degrees.
    pub range: Option<(f64, f64)>,
    /// Loop closure.
    pub closure: Option<Closure>,
    /// Output directory.
    pub out: PathBuf,
    /// File stem.
    pub name: Option<String>,
}

impl Default for Args {
    fn default() -> Self {
        Self {
            axis: None,
            seed: None,
            n: None,
            w: None,
            range: None,
            closure: None,
            out: PathBuf::from("preview"),
            name: None,
        }
    }
}

/// One loop to preview.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopSpec {
    /// The axis (anatomical limits).
    pub axis: Axis,
    /// Samples per loop.
    pub n: usize,
    /// Seed, window, step, range and closure.
    pub cfg: AxisConfig,
}

impl Args {
    /// Parses the options after `preview`; `Ok(None)` asks for help.
    pub fn parse(mut rest: impl Iterator<Item = String>) -> Result<Option<Self>> {
        let mut parsed = Self::default();
        while let Some(arg) = rest.next() {
            let (flag, inline) = args::split(&arg);
            let mut value =
                |what: &str| -> Result<String> { args::value(flag, inline, &mut rest, what) };
            match flag {
                "-h" | "--help" => return Ok(None),
                "--axis" => {
                    let name = value("an axis (pitch, roll or yaw)")?;
                    parsed.axis = Some(
                        Axis::ALL
                            .into_iter()
                            .find(|axis| axis.name().eq_ignore_ascii_case(&name))
                            .with_context(|| {
                                format!("`--axis {name}`: expected pitch, roll or yaw")
                            })?,
                    );
                }
                "--seed" => {
                    parsed.seed = Some(args::parse(flag, &value("a seed")?, "a u32 seed")?);
                }
                "--n" => {
                    parsed.n = Some(args::parse(
                        flag,
                        &value("a number of samples")?,
                        "a number of samples",
                    )?);
                }
                "--w" => {
                    parsed.w = Some(args::parse(
                        flag,
                        &value("a window length")?,
                        "a window length in taps",
                    )?);
                }
                "--range" => {
                    if inline.is_some() {
                        bail!("`--range` takes two values: `--range <a1> <a2>`");
                    }
                    let a1 = value("two angles in degrees")?;
                    let a2 = rest
                        .next()
                        .context("`--range` needs two angles in degrees: `--range <a1> <a2>`")?;
                    parsed.range = Some((
                        args::parse(flag, &a1, "an angle in degrees")?,
                        args::parse(flag, &a2, "an angle in degrees")?,
                    ));
                }
                "--closure" => {
                    let name = value("paper or seamless")?;
                    parsed.closure = Some(match name.to_ascii_lowercase().as_str() {
                        "paper" => Closure::Paper,
                        "seamless" => Closure::Seamless,
                        _ => bail!("`--closure {name}`: expected paper or seamless"),
                    });
                }
                "--out" => parsed.out = PathBuf::from(value("a directory")?),
                "--name" => {
                    let stem = value("a file name stem")?;
                    if stem.is_empty() || stem.contains(['/', '\\']) {
                        bail!("`--name {stem}`: expected a file name stem without a directory");
                    }
                    parsed.name = Some(stem);
                }
                other => bail!("unknown preview option `{other}` (see `cargo xtask help`)"),
            }
        }
        Ok(Some(parsed))
    }

    /// Whether any option selects a single loop.
    fn single(&self) -> bool {
        self.axis.is_some()
            || self.seed.is_some()
            || self.n.is_some()
            || self.w.is_some()
            || self.range.is_some()
            || self.closure.is_some()
    }

    /// The loops to preview with their file stems, validated: the three
    /// default axes with no loop option, else one loop.
    pub fn loops(&self) -> Result<Vec<(LoopSpec, String)>> {
        let specs = if self.single() {
            let axis = self.axis.unwrap_or(Axis::Yaw);
            let mut cfg = *DEFAULT_HEAD.axis(axis);
            if let Some(seed) = self.seed {
                cfg.seed = seed;
            }
            if let Some(w) = self.w {
                cfg.window = w;
            }
            if let Some((a1, a2)) = self.range {
                cfg.range = AngleRange {
                    min: degrees(a1)?,
                    max: degrees(a2)?,
                };
            }
            if let Some(closure) = self.closure {
                cfg.closure = closure;
            }
            let name = self.name.clone().unwrap_or_else(|| "loop".to_owned());
            vec![(
                LoopSpec {
                    axis,
                    n: self.n.unwrap_or(DEFAULT_N),
                    cfg,
                },
                name,
            )]
        } else {
            Axis::ALL
                .into_iter()
                .map(|axis| {
                    let spec = LoopSpec {
                        axis,
                        n: DEFAULT_N,
                        cfg: *DEFAULT_HEAD.axis(axis),
                    };
                    let name = match &self.name {
                        Some(stem) => format!("{stem}-{}", axis.name()),
                        None => axis.name().to_owned(),
                    };
                    (spec, name)
                })
                .collect()
        };
        for (spec, _) in &specs {
            spec.cfg
                .validate(spec.axis, spec.n)
                .map_err(|error| anyhow!("{}: {error}", spec.axis.name()))?;
        }
        Ok(specs)
    }
}

/// Degrees (decimal) to an [`Angle`], to the nearest millidegree.
fn degrees(value: f64) -> Result<Angle> {
    let mdeg = (value * f64::from(Angle::SCALE)).round();
    if !mdeg.is_finite() || mdeg.abs() > f64::from(i16::MAX) {
        bail!("angle {value}° is out of reach (at most ±32.767°)");
    }
    Ok(Angle::from_millidegrees(mdeg as i32))
}

/// An [`Angle`] in degrees.
fn deg(angle: Angle) -> f64 {
    f64::from(angle.millidegrees()) / f64::from(Angle::SCALE)
}

/// The paper closure's open walk in degrees: u(0) = 0, u(n) = u(n−1) ± δ with
/// the sign of r(n).
pub fn paper_walk(seed: u32, n: usize, delta: f64) -> Vec<f64> {
    let mut lcg = Lcg::new(seed);
    let mut u = 0.0;
    (0..n)
        .map(|i| {
            if i > 0 {
                u += f64::from(step_of(lcg.next_value())) * delta;
            }
            u
        })
        .collect()
}

/// The seamless closure's periodic walk in degrees: e(k) = ±1 from r(k+1),
/// walk(n) = δ·Σ_{k≤n} (e(k) − D/N) with D = Σ e; walk(N−1) = 0.
pub fn seamless_walk(seed: u32, n: usize, delta: f64) -> Vec<f64> {
    let mut lcg = Lcg::new(seed);
    let steps: Vec<f64> = (0..n)
        .map(|_| f64::from(step_of(lcg.next_value())))
        .collect();
    let drift = steps.iter().sum::<f64>() / n as f64;
    let mut u = 0.0;
    steps
        .iter()
        .map(|e| {
            u += (e - drift) * delta;
            u
        })
        .collect()
}

/// The paper's normalisation into [a1, a2]: a1 + (s − min)(a2 − a1)/(max − min).
pub fn normalize(values: &[f64], a1: f64, a2: f64) -> Vec<f64> {
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let span = max - min;
    values
        .iter()
        .map(|&s| {
            if span > 0.0 {
                a1 + (s - min) * (a2 - a1) / span
            } else {
                a1
            }
        })
        .collect()
}

/// The length-N Hann taper of the paper closure: ½ − ½·cos(2πn/(N−1)).
pub fn taper(n: usize) -> Vec<f64> {
    let span = (n.max(2) - 1) as f64;
    (0..n)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / span).cos())
        .collect()
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len().max(1) as f64
}

/// Records the engine's intermediate stages (generation order).
struct Recorder {
    /// The smoothed walk in walk steps δ.
    smoothed: Vec<f64>,
    /// The scaled loop before closure, fine units (1/256 m°).
    scaled: Vec<i32>,
}

impl Trace for Recorder {
    fn smoothed(&mut self, n: usize, walk_steps: f32) {
        if let Some(slot) = self.smoothed.get_mut(n) {
            *slot = f64::from(walk_steps);
        }
    }

    fn normalized(&mut self, n: usize, fine: i32) {
        if let Some(slot) = self.scaled.get_mut(n) {
            *slot = fine;
        }
    }
}

/// What the data say about the split point p.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitCheck {
    /// max |final(i) − last(i + p mod N)| over i, degrees: ≈ 0 if index 0 of
    /// the stored loop is sample p of the closure's last stage.
    pub forward: f64,
    /// The same for the other reading, final(i) = last(i − p mod N).
    pub backward: f64,
    /// The normalised loop at p, degrees (≈ 0: p is a crossing of zero).
    pub normalized_at_p: f64,
    /// max |normalized − the engine's own scaled stage|, degrees (≈ 0 for
    /// the paper closure, whose engine normalises exactly so).
    pub formula_vs_engine: f64,
}

/// All stages of one loop.
#[derive(Debug, Clone)]
pub struct Stages {
    /// What was generated.
    pub spec: LoopSpec,
    /// The engine's decisions.
    pub info: LoopInfo,
    /// Walk, degrees, generation order.
    pub walk: Vec<f64>,
    /// Smoothed walk, degrees, generation order.
    pub smoothed: Vec<f64>,
    /// Normalised into [α1, α2], degrees, generation order.
    pub normalized: Vec<f64>,
    /// Paper closure only: the Hann taper and the tapered loop (degrees).
    pub tapered: Option<(Vec<f64>, Vec<f64>)>,
    /// The stored loop, degrees, playback order.
    pub final_loop: Vec<f64>,
    /// Metrics of the stored loop.
    pub metrics: LoopMetrics,
    /// The split point, checked against the data.
    pub split: SplitCheck,
}

impl Stages {
    /// Runs the engine for `spec` and derives every stage.
    pub fn compute(spec: LoopSpec) -> Result<Self> {
        let LoopSpec { axis, n, cfg } = spec;
        let kernel = HannKernel::new(cfg.window).map_err(|error| anyhow!("{error}"))?;
        let mut stored = vec![Mdeg16(0); n];
        let mut recorder = Recorder {
            smoothed: vec![0.0; n],
            scaled: vec![0; n],
        };
        let info = generate_into(&mut stored, &cfg, axis, &kernel, &mut recorder)
            .map_err(|error| anyhow!("{}: {error}", axis.name()))?;

        let delta = deg(cfg.step);
        let walk = match cfg.closure {
            Closure::Paper => paper_walk(cfg.seed, n, delta),
            Closure::Seamless => seamless_walk(cfg.seed, n, delta),
        };
        let mut smoothed: Vec<f64> = recorder.smoothed.iter().map(|s| s * delta).collect();
        let shift = mean(&walk) - mean(&smoothed);
        for s in &mut smoothed {
            *s += shift;
        }
        let (a1, a2) = (deg(cfg.range.min), deg(cfg.range.max));
        let normalized = normalize(&smoothed, a1, a2);
        let final_loop: Vec<f64> = stored.iter().map(|s| f64::from(s.0) / 1000.0).collect();

        // The closure's last stage before the exchange, from the engine's own
        // scaled values (fine units), in degrees.
        let fine_to_deg = |fine: i32| f64::from(fine) / f64::from(FINE_PER_MDEG * Angle::SCALE);
        let scaled: Vec<f64> = recorder.scaled.iter().map(|&f| fine_to_deg(f)).collect();
        let (last, tapered) = match cfg.closure {
            Closure::Paper => {
                let h = taper(n);
                let last: Vec<f64> = scaled.iter().zip(&h).map(|(x, h)| x * h).collect();
                let mine: Vec<f64> = normalized.iter().zip(&h).map(|(x, h)| x * h).collect();
                (last, Some((h, mine)))
            }
            Closure::Seamless => (scaled.clone(), None),
        };
        let p = usize::from(info.split);
        let distance = |offset: usize| {
            final_loop
                .iter()
                .enumerate()
                .map(|(i, f)| (f - last[(i + offset) % n]).abs())
                .fold(0.0, f64::max)
        };
        let split = SplitCheck {
            forward: distance(p),
            backward: distance((n - p % n) % n),
            normalized_at_p: normalized.get(p).copied().unwrap_or(f64::NAN),
            formula_vs_engine: normalized
                .iter()
                .zip(&scaled)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max),
        };

        let mut scratch = vec![0; n];
        let metrics = LoopMetrics::measure(&stored, &mut scratch)
            .context("the loop is too short to measure")?;
        Ok(Self {
            spec,
            info,
            walk,
            smoothed,
            normalized,
            tapered,
            final_loop,
            metrics,
            split,
        })
    }

    /// The CSV text: header `n,walk,smoothed,normalized,final`, degrees.
    pub fn csv(&self) -> String {
        let mut out = String::from("n,walk,smoothed,normalized,final\n");
        for i in 0..self.spec.n {
            let _ = writeln!(
                out,
                "{i},{:.4},{:.4},{:.4},{:.3}",
                self.walk[i], self.smoothed[i], self.normalized[i], self.final_loop[i]
            );
        }
        out
    }

    /// One line naming the loop.
    pub fn title(&self) -> String {
        let LoopSpec { axis, n, cfg } = self.spec;
        format!(
            "{}: seed r(0) = {}, N = {n}, W = {}, δ = {}°, range [α1, α2] = [{}°, {}°], {} closure",
            axis.name(),
            cfg.seed,
            cfg.window,
            deg(cfg.step),
            deg(cfg.range.min),
            deg(cfg.range.max),
            closure_name(cfg.closure),
        )
    }

    /// The metrics as short lines (the PNG's text box and the terminal).
    pub fn metric_lines(&self) -> Vec<String> {
        let m = &self.metrics;
        let LoopSpec { cfg, .. } = self.spec;
        let inside = cfg.range.contains(m.min) && cfg.range.contains(m.max);
        vec![
            format!(
                "continuity: max|d1|/P95|d1| = {:.2}, max|d2|/P95|d2| = {:.2}",
                m.velocity_ratio, m.acceleration_ratio
            ),
            format!(
                "liveliness (min over 10 segments of mean|d1| / mean|d1|) = {:.2}",
                m.liveliness
            ),
            format!(
                "range: min = {:.3}°, max = {:.3}° ({} [{}°, {}°]); start x(0) = {:.3}°",
                deg(m.min),
                deg(m.max),
                if inside { "inside" } else { "OUTSIDE" },
                deg(cfg.range.min),
                deg(cfg.range.max),
                deg(m.start),
            ),
            match cfg.closure {
                Closure::Paper => format!(
                    "split p = {} (drawn from {} zero crossings); {} up-steps in the walk",
                    self.info.split, self.info.crossings, self.info.up_steps
                ),
                Closure::Seamless => format!(
                    "split p = {} (where the smoothed loop crosses the level that maps to 0°); \
                     {} up-steps in the walk",
                    self.info.split, self.info.up_steps
                ),
            },
        ]
    }

    /// What the split check found, in words.
    pub fn split_lines(&self) -> Vec<String> {
        let s = &self.split;
        let p = self.info.split;
        let stage = match self.spec.cfg.closure {
            Closure::Paper => "the tapered loop",
            Closure::Seamless => "the engine's scaled loop",
        };
        vec![
            format!(
                "split check: final(i) = {stage}((i + p) mod N) within {:.4}° \
                 (the reading (i − p) mod N is off by up to {:.3}°)",
                s.forward, s.backward
            ),
            format!(
                "             normalized(p = {p}) = {:.4}° (p sits at a crossing of zero); \
                 paper formula vs the engine's scaling: max diff {:.4}°",
                s.normalized_at_p, s.formula_vs_engine
            ),
        ]
    }
}

fn closure_name(closure: Closure) -> &'static str {
    match closure {
        Closure::Paper => "paper",
        Closure::Seamless => "seamless",
    }
}

/// `cargo xtask preview`.
pub fn command(options: &Args) -> Result<bool> {
    let loops = options.loops()?;
    fs::create_dir_all(&options.out)
        .with_context(|| format!("creating {}", options.out.display()))?;
    for (spec, stem) in loops {
        let stages = Stages::compute(spec)?;
        let csv = options.out.join(format!("{stem}.csv"));
        let png = options.out.join(format!("{stem}.png"));
        fs::write(&csv, stages.csv()).with_context(|| format!("writing {}", csv.display()))?;
        plot(&stages, &png)?;
        println!("{}", stages.title());
        for line in stages.metric_lines().iter().chain(&stages.split_lines()) {
            println!("  {line}");
        }
        println!("  wrote {} and {}", csv.display(), png.display());
    }
    Ok(true)
}

// ---------------------------------------------------------------------------
// The PNG
// ---------------------------------------------------------------------------

const WIDTH: u32 = 1400;
const HEADER: u32 = 150;
const PANEL: u32 = 240;
/// Width of the legend column right of each panel.
const LEGEND: u32 = 270;
const FONT: &str = "sans-serif";

/// Registers `DejaVu Sans` as the plots' `sans-serif` font, once.
fn register_fonts() -> Result<()> {
    static ONCE: Once = Once::new();
    let mut result = Ok(());
    ONCE.call_once(|| {
        for (style, bytes) in [
            (FontStyle::Normal, dejavu::sans::regular()),
            (FontStyle::Bold, dejavu::sans::bold()),
        ] {
            if register_font(FONT, style, bytes).is_err() {
                result = Err(anyhow!("the DejaVu Sans font did not load"));
            }
        }
    });
    result
}

/// One curve of a panel.
struct Curve<'a> {
    label: String,
    values: &'a [f64],
    color: RGBColor,
}

/// One panel of the figure.
struct Panel<'a> {
    title: String,
    x_desc: &'static str,
    y_desc: &'static str,
    curves: Vec<Curve<'a>>,
    /// Dashed horizontal lines at α1 and α2.
    range: Option<(f64, f64)>,
    /// Vertical markers: index and label.
    markers: Vec<(usize, String)>,
}

const BLUE_: RGBColor = RGBColor(31, 119, 180);
const ORANGE: RGBColor = RGBColor(255, 127, 14);
const GREEN_: RGBColor = RGBColor(44, 160, 44);
const RED_: RGBColor = RGBColor(214, 39, 40);
const PURPLE: RGBColor = RGBColor(148, 103, 189);
const GREY: RGBColor = RGBColor(110, 110, 110);

#[allow(clippy::too_many_lines)] // one literal per panel
fn panels(stages: &Stages) -> Vec<Panel<'_>> {
    let LoopSpec { n, cfg, .. } = stages.spec;
    let range = (deg(cfg.range.min), deg(cfg.range.max));
    let p = usize::from(stages.info.split);
    let generation = "sample index n (generation order)";
    let degrees = "angle (°)";
    let split_label = format!("split p = {p}");
    let mut panels = vec![
        Panel {
            title: match cfg.closure {
                Closure::Paper => "1. random walk u(n) = u(n−1) ± δ".to_owned(),
                Closure::Seamless => "1. periodic random walk (mean step removed)".to_owned(),
            },
            x_desc: generation,
            y_desc: degrees,
            curves: vec![Curve {
                label: "walk".to_owned(),
                values: &stages.walk,
                color: GREY,
            }],
            range: None,
            markers: vec![],
        },
        Panel {
            title: format!(
                "2. smoothed with a {}-tap Hann window ({})",
                cfg.window,
                match cfg.closure {
                    Closure::Paper => "causal",
                    Closure::Seamless => "circular",
                }
            ),
            x_desc: generation,
            y_desc: degrees,
            curves: vec![
                Curve {
                    label: "walk".to_owned(),
                    values: &stages.walk,
                    color: RGBColor(190, 190, 190),
                },
                Curve {
                    label: "smoothed".to_owned(),
                    values: &stages.smoothed,
                    color: BLUE_,
                },
            ],
            range: None,
            markers: vec![],
        },
        Panel {
            title: "3. normalised into [α1, α2]".to_owned(),
            x_desc: generation,
            y_desc: degrees,
            curves: vec![Curve {
                label: "normalised".to_owned(),
                values: &stages.normalized,
                color: ORANGE,
            }],
            range: Some(range),
            markers: vec![(p, split_label.clone())],
        },
    ];
    if let Some((taper, tapered)) = &stages.tapered {
        panels.push(Panel {
            title: "4. Hann taper ½ − ½·cos(2πn/(N−1))".to_owned(),
            x_desc: generation,
            y_desc: "weight",
            curves: vec![Curve {
                label: "taper".to_owned(),
                values: taper,
                color: PURPLE,
            }],
            range: None,
            markers: vec![],
        });
        panels.push(Panel {
            title: "5. normalised × taper: both ends at zero".to_owned(),
            x_desc: generation,
            y_desc: degrees,
            curves: vec![Curve {
                label: "tapered".to_owned(),
                values: tapered,
                color: GREEN_,
            }],
            range: Some(range),
            markers: vec![(p, split_label)],
        });
    }
    let seam = (n - p % n) % n;
    let mut markers = vec![(0, format!("start = sample p = {p}"))];
    if seam != 0 {
        markers.push((seam, format!("seam: samples N−1 | 0 (index {seam})")));
    }
    panels.push(Panel {
        title: format!(
            "{}. final loop, stored (0.001° steps), in playback order: halves exchanged at p",
            panels.len() + 1
        ),
        x_desc: "playback index i (final(i) = stage(i + p mod N))",
        y_desc: degrees,
        curves: vec![Curve {
            label: "final".to_owned(),
            values: &stages.final_loop,
            color: RED_,
        }],
        range: Some(range),
        markers,
    });
    panels
}

/// Draws the figure to `path` (PNG).
pub fn plot(stages: &Stages, path: &Path) -> Result<()> {
    register_fonts()?;
    let panels = panels(stages);
    let height = HEADER + PANEL * panels.len() as u32;
    let root = BitMapBackend::new(path, (WIDTH, height)).into_drawing_area();
    draw(&root, stages, &panels).map_err(|error| anyhow!("drawing {}: {error}", path.display()))?;
    root.present()
        .map_err(|error| anyhow!("writing {}: {error}", path.display()))?;
    Ok(())
}

type DrawResult<T> = Result<T, Box<dyn std::error::Error>>;

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    stages: &Stages,
    panels: &[Panel<'_>],
) -> DrawResult<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (header, body) = root.split_vertically(HEADER);
    header.draw(&Text::new(
        stages.title(),
        (20, 14),
        (FONT, 24).into_font().style(FontStyle::Bold),
    ))?;
    header.draw(&Text::new(
        "Idle-loop generation after Kocoń, section 3 (stages as in Figures 6 and 7)",
        (20, 46),
        (FONT, 16).into_font().color(&GREY),
    ))?;
    // The metrics text box.
    let lines = stages.metric_lines();
    let (x0, y0) = (20, 72);
    let line_height = 17;
    header.draw(&Rectangle::new(
        [
            (x0 - 8, y0 - 6),
            (x0 + 760, y0 + line_height * lines.len() as i32 + 2),
        ],
        ShapeStyle::from(&RGBColor(245, 245, 240)).filled(),
    ))?;
    header.draw(&Rectangle::new(
        [
            (x0 - 8, y0 - 6),
            (x0 + 760, y0 + line_height * lines.len() as i32 + 2),
        ],
        GREY.stroke_width(1),
    ))?;
    for (i, line) in lines.iter().enumerate() {
        header.draw(&Text::new(
            line.clone(),
            (x0, y0 + line_height * i as i32),
            (FONT, 14),
        ))?;
    }

    let areas = body.split_evenly((panels.len(), 1));
    for (area, panel) in areas.iter().zip(panels) {
        draw_panel(area, panel, stages.spec.n)?;
    }
    Ok(())
}

/// How a legend entry is drawn.
#[derive(Clone, Copy)]
enum Key {
    Line(RGBColor),
    Dashed(RGBColor),
    Marker(RGBColor),
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel<'_>,
    n: usize,
) -> DrawResult<()>
where
    DB::ErrorType: 'static,
{
    let (plot_area, legend_area) = area.split_horizontally(WIDTH - LEGEND);
    let (mut lo, mut hi) = panel
        .curves
        .iter()
        .flat_map(|curve| curve.values.iter().copied())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if let Some((a1, a2)) = panel.range {
        lo = lo.min(a1);
        hi = hi.max(a2);
    }
    let pad = ((hi - lo) * 0.08).max(1e-3);
    let (lo, hi) = (lo - pad, hi + pad);
    let x_max = (n.max(2) - 1) as f64;

    let mut chart = ChartBuilder::on(&plot_area)
        .caption(&panel.title, (FONT, 17).into_font().style(FontStyle::Bold))
        .margin(8)
        .margin_right(16)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..x_max, lo..hi)?;
    chart
        .configure_mesh()
        .x_desc(panel.x_desc)
        .y_desc(panel.y_desc)
        .axis_desc_style((FONT, 14))
        .label_style((FONT, 13))
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.1}"))
        .max_light_lines(1)
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(218, 218, 218))
        .x_labels(19)
        .y_labels(6)
        .draw()?;

    let mut keys: Vec<(String, Key)> = Vec::new();
    for curve in &panel.curves {
        chart.draw_series(LineSeries::new(
            curve.values.iter().enumerate().map(|(i, &v)| (i as f64, v)),
            curve.color.stroke_width(2),
        ))?;
        keys.push((curve.label.clone(), Key::Line(curve.color)));
    }
    if let Some((a1, a2)) = panel.range {
        for level in [a1, a2] {
            chart.draw_series(DashedLineSeries::new(
                [(0.0, level), (x_max, level)],
                8,
                6,
                GREY.stroke_width(1),
            ))?;
        }
        keys.push((format!("[α1, α2] = [{a1}°, {a2}°]"), Key::Dashed(GREY)));
    }
    for (k, (index, label)) in panel.markers.iter().enumerate() {
        let x = *index as f64;
        let color = if k == 0 { RED_ } else { BLACK };
        let value = panel
            .curves
            .last()
            .and_then(|curve| curve.values.get(*index))
            .copied()
            .unwrap_or(0.0);
        chart.draw_series(DashedLineSeries::new(
            [(x, lo), (x, hi)],
            5,
            4,
            color.stroke_width(2),
        ))?;
        chart.draw_series(std::iter::once(Circle::new((x, value), 5, color.filled())))?;
        keys.push((label.clone(), Key::Marker(color)));
    }
    draw_legend(&legend_area, &keys)
}

/// The legend of a panel, in the column to the right of its plot.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    keys: &[(String, Key)],
) -> DrawResult<()>
where
    DB::ErrorType: 'static,
{
    let (x, mut y) = (6, 40);
    let row = 22;
    let bottom = y + row * (keys.len().max(1) as i32 - 1) + 13;
    area.draw(&Rectangle::new(
        [(x - 4, y - 13), (LEGEND as i32 - 10, bottom)],
        GREY.mix(0.6).stroke_width(1),
    ))?;
    let text = TextStyle::from((FONT, 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (label, key) in keys {
        match *key {
            Key::Line(color) => {
                area.draw(&PathElement::new(
                    vec![(x + 4, y), (x + 30, y)],
                    color.stroke_width(3),
                ))?;
            }
            Key::Dashed(color) => {
                for dash in [(x + 4, x + 11), (x + 15, x + 22), (x + 26, x + 30)] {
                    area.draw(&PathElement::new(
                        vec![(dash.0, y), (dash.1, y)],
                        color.stroke_width(1),
                    ))?;
                }
            }
            Key::Marker(color) => {
                area.draw(&PathElement::new(
                    vec![(x + 17, y - 8), (x + 17, y + 8)],
                    color.stroke_width(2),
                ))?;
                area.draw(&Circle::new((x + 17, y), 4, color.filled()))?;
            }
        }
        area.draw(&Text::new(label.clone(), (x + 38, y), text.clone()))?;
        y += row;
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact values by construction
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Result<Option<Args>> {
        Args::parse(args.iter().map(|s| (*s).to_owned()))
    }

    #[test]
    fn no_arguments_preview_the_three_default_axes() {
        let args = parse(&[]).unwrap().unwrap();
        assert_eq!(args.out, PathBuf::from("preview"));
        let loops = args.loops().unwrap();
        let names: Vec<&str> = loops.iter().map(|(_, name)| name.as_str()).collect();
        assert_eq!(names, ["pitch", "roll", "yaw"]);
        assert_eq!(loops[0].0.cfg, DEFAULT_HEAD.pitch);
        assert_eq!(loops[2].0.n, DEFAULT_N);
        // --out alone keeps the default preview.
        let args = parse(&["--out", "x"]).unwrap().unwrap();
        assert_eq!(args.loops().unwrap().len(), 3);
    }

    #[test]
    fn one_loop_from_options() {
        let args = parse(&[
            "--seed",
            "127",
            "--n=450",
            "--w",
            "31",
            "--range",
            "-4.5",
            "12",
            "--closure",
            "paper",
            "--out",
            "tmp",
            "--axis",
            "pitch",
        ])
        .unwrap()
        .unwrap();
        let loops = args.loops().unwrap();
        assert_eq!(loops.len(), 1);
        let (spec, name) = &loops[0];
        assert_eq!(name, "loop");
        assert_eq!(spec.axis, Axis::Pitch);
        assert_eq!(spec.n, 450);
        assert_eq!(spec.cfg.seed, 127);
        assert_eq!(spec.cfg.window, 31);
        assert_eq!(spec.cfg.range.min, Angle::from_millidegrees(-4500));
        assert_eq!(spec.cfg.range.max, Angle::from_degrees(12));
        assert_eq!(spec.cfg.closure, Closure::Paper);
        assert_eq!(args.out, PathBuf::from("tmp"));
    }

    #[test]
    fn bad_options_are_named() {
        assert!(parse(&["--help"]).unwrap().is_none());
        let error = |args: &[&str]| format!("{:#}", parse(args).unwrap_err());
        assert!(error(&["--closure", "smooth"]).contains("paper or seamless"));
        assert!(error(&["--range", "1"]).contains("two angles"));
        assert!(error(&["--seed", "-1"]).contains("--seed"));
        assert!(error(&["--bogus"]).contains("--bogus"));
        // Rejected by the library's validation, with its message.
        let args = parse(&["--range", "-30", "10"]).unwrap().unwrap();
        assert!(format!("{:#}", args.loops().unwrap_err()).contains("anatomical"));
        let args = parse(&["--w", "2"]).unwrap().unwrap();
        assert!(format!("{:#}", args.loops().unwrap_err()).contains("window"));
    }

    #[test]
    fn paper_walk_steps_by_the_top_bit_of_r_n() {
        let walk = paper_walk(127, 6, 0.5);
        assert_eq!(walk[0], 0.0);
        let mut lcg = Lcg::new(127);
        for i in 1..6 {
            let r = lcg.next_value();
            let step = if r >= 1 << 31 { 0.5 } else { -0.5 };
            assert_eq!(walk[i] - walk[i - 1], step);
        }
    }

    #[test]
    fn seamless_walk_is_periodic() {
        let walk = seamless_walk(8821, 900, 1.0);
        assert!(walk[899].abs() < 1e-9, "ends at zero: {}", walk[899]);
        // The first step is e(0) − D/N, with e(0) from r(1).
        let mut lcg = Lcg::new(8821);
        let e0 = f64::from(step_of(lcg.next_value()));
        assert!((walk[0] - e0).abs() < 1.0);
    }

    #[test]
    fn normalisation_and_taper() {
        assert_eq!(normalize(&[2.0, 4.0, 3.0], -4.0, 12.0), [-4.0, 12.0, 4.0]);
        assert_eq!(normalize(&[1.0, 1.0], -1.0, 1.0), [-1.0, -1.0]);
        let h = taper(5);
        assert!(h[0].abs() < 1e-12 && h[4].abs() < 1e-12);
        assert!((h[2] - 1.0).abs() < 1e-12);
        assert!((h[1] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn stages_of_a_default_axis() {
        for closure in [Closure::Paper, Closure::Seamless] {
            let spec = LoopSpec {
                axis: Axis::Pitch,
                n: DEFAULT_N,
                cfg: DEFAULT_HEAD.pitch.with_closure(closure),
            };
            let stages = Stages::compute(spec).unwrap();
            // Playback starts at the split point of the last stage.
            assert!(stages.split.forward <= 0.001, "{:?}", stages.split);
            // The split is a crossing of zero of the normalised loop: within
            // one sample's step of it.
            assert!(
                stages.split.normalized_at_p.abs() < 0.2,
                "{:?}",
                stages.split
            );
            let (lo, hi) = stages
                .normalized
                .iter()
                .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
            assert!((lo + 4.0).abs() < 1e-9 && (hi - 12.0).abs() < 1e-9);
            if closure == Closure::Paper {
                assert!(stages.split.formula_vs_engine < 0.01, "{:?}", stages.split);
            }
            let csv = stages.csv();
            let mut lines = csv.lines();
            assert_eq!(lines.next(), Some("n,walk,smoothed,normalized,final"));
            assert_eq!(lines.count(), DEFAULT_N);
            let smoothed_mean = mean(&stages.smoothed);
            assert!((smoothed_mean - mean(&stages.walk)).abs() < 1e-9);
        }
    }
}
