//! The stages of one loop in f64 degrees from the engine's own trace
//! (`walk`, `smoothed`, shifted to the walk's mean as the engine leaves its
//! constant open, `normalized`, `final`), its metrics and its figure.

// Sample indices (< 2^13) and angles are small: float conversions are exact
// or far below the printed resolution.
#![allow(clippy::cast_precision_loss)]

use std::{fmt::Write as _, path::Path};

use anyhow::{Context, Result};
use plotters::style::RGBColor;

use crate::plot::{self, BLUE, Curve, Figure, GREEN, GREY, LIGHT, ORANGE, PURPLE, Panel, RED};
use idle_head_core::{
    Angle, Axis,
    metrics::LoopMetrics,
    motion::{
        AxisConfig, AxisError, Closure, HannKernel, Lcg, LoopInfo, Mdeg16, Trace, generate_into,
        step_of,
    },
};

/// One loop to preview: its axis, length, and configuration (seed, window,
/// step, range and closure).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopSpec {
    pub axis: Axis,
    pub n: usize,
    pub cfg: AxisConfig,
}

pub fn deg(angle: Angle) -> f64 {
    f64::from(angle.millidegrees()) / f64::from(Angle::SCALE)
}

pub fn closure_name(closure: Closure) -> &'static str {
    match closure {
        Closure::Paper => "paper",
        Closure::Seamless => "seamless",
    }
}

/// The closure's walk in degrees. Paper: the open walk u(0) = 0, u(n) =
/// u(n−1) ± δ with the sign of r(n). Seamless: the periodic walk, e(k) = ±1
/// from r(k+1), walk(n) = δ·Σ_{k≤n} (e(k) − D/N) with D = Σ e; walk(N−1) = 0.
fn walk(closure: Closure, seed: u32, n: usize, delta: f64) -> Vec<f64> {
    let mut lcg = Lcg::new(seed);
    let mut steps: Vec<f64> = (0..n)
        .map(|_| f64::from(step_of(lcg.next_value())))
        .collect();
    let drift = match closure {
        Closure::Paper => {
            steps.insert(0, 0.0);
            steps.truncate(n);
            0.0
        }
        Closure::Seamless => steps.iter().sum::<f64>() / n as f64,
    };
    let walk = steps.iter().scan(0.0, |u, e| {
        *u += (e - drift) * delta;
        Some(*u)
    });
    walk.collect()
}

/// The paper's normalisation into [a1, a2]: a1 + (s − min)(a2 − a1)/(max − min).
pub fn normalize(values: &[f64], a1: f64, a2: f64) -> Vec<f64> {
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    // A flat stage (no span) maps to a1.
    let span = (max - min).max(f64::MIN_POSITIVE);
    let scale = |s: &f64| a1 + (s - min) * (a2 - a1) / span;
    values.iter().map(scale).collect()
}

/// The length-N Hann taper of the paper closure: ½ − ½·cos(2πn/(N−1)).
pub fn taper(n: usize) -> Vec<f64> {
    let span = (n.max(2) - 1) as f64;
    let weight = |i: usize| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / span).cos();
    (0..n).map(weight).collect()
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len().max(1) as f64
}

/// Records the engine's smoothed walk (generation order), in walk steps δ.
struct Recorder(Vec<f64>);

impl Trace for Recorder {
    fn smoothed(&mut self, n: usize, walk_steps: f32) {
        if let Some(slot) = self.0.get_mut(n) {
            *slot = f64::from(walk_steps);
        }
    }
}

/// All stages of one loop, in degrees, in generation order but the stored
/// loop (playback order); the paper closure's Hann taper and tapered loop;
/// the stored loop's metrics.
#[derive(Debug, Clone)]
pub struct Stages {
    pub spec: LoopSpec,
    pub info: LoopInfo,
    pub walk: Vec<f64>,
    pub smoothed: Vec<f64>,
    pub normalized: Vec<f64>,
    pub tapered: Option<(Vec<f64>, Vec<f64>)>,
    pub final_loop: Vec<f64>,
    pub metrics: LoopMetrics,
}

impl Stages {
    /// Runs the engine for `spec` and derives every stage.
    pub fn compute(spec: LoopSpec) -> Result<Self> {
        let LoopSpec { axis, n, cfg } = spec;
        let kernel = HannKernel::new(cfg.window).map_err(|error| AxisError { axis, error })?;
        let mut stored = vec![Mdeg16(0); n];
        let mut recorder = Recorder(vec![0.0; n]);
        let info = generate_into(&mut stored, &cfg, axis, &kernel, &mut recorder)
            .map_err(|error| AxisError { axis, error })?;

        let delta = deg(cfg.step);
        let walk = walk(cfg.closure, cfg.seed, n, delta);
        let smoothed: Vec<f64> = recorder.0.iter().map(|s| s * delta).collect();
        let shift = mean(&walk) - mean(&smoothed);
        let smoothed: Vec<f64> = smoothed.iter().map(|s| s + shift).collect();
        let (a1, a2) = (deg(cfg.range.min), deg(cfg.range.max));
        let normalized = normalize(&smoothed, a1, a2);
        let final_loop: Vec<f64> = stored.iter().map(|s| f64::from(s.0) / 1000.0).collect();

        let tapered = (cfg.closure == Closure::Paper).then(|| {
            let h = taper(n);
            let tapered = normalized.iter().zip(&h).map(|(x, h)| x * h).collect();
            (h, tapered)
        });
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
        let (d1, d2, lively) = (m.velocity_ratio, m.acceleration_ratio, m.liveliness);
        let split = match cfg.closure {
            Closure::Paper => format!("drawn from {} zero crossings", self.info.crossings),
            Closure::Seamless => "where the smoothed loop crosses the level that maps to 0°".into(),
        };
        vec![
            format!("continuity: max|d1|/P95|d1| = {d1:.2}, max|d2|/P95|d2| = {d2:.2}"),
            format!("liveliness (min over 10 segments of mean|d1| / mean|d1|) = {lively:.2}"),
            format!(
                "range: min = {:.3}°, max = {:.3}° ({} [{}°, {}°]); start x(0) = {:.3}°",
                deg(m.min),
                deg(m.max),
                if inside { "inside" } else { "OUTSIDE" },
                deg(cfg.range.min),
                deg(cfg.range.max),
                deg(m.start),
            ),
            format!(
                "split p = {} ({split}); {} up-steps in the walk",
                self.info.split, self.info.up_steps
            ),
        ]
    }
}

/// Draws a loop's stages (`cargo xtask preview`) to `path`: stacked panels
/// in the style of the paper's Figures 6 and 7, the split point marked, the
/// loop's metrics under the title.
pub fn draw(stages: &Stages, path: &Path) -> Result<()> {
    let (n, cfg, p) = (stages.spec.n, stages.spec.cfg, stages.info.split);
    let (a1, a2) = (deg(cfg.range.min), deg(cfg.range.max));
    let (walk, window) = match cfg.closure {
        Closure::Paper => ("random walk u(n) = u(n−1) ± δ", "causal"),
        Closure::Seamless => ("periodic random walk (mean step removed)", "circular"),
    };
    let split = (f64::from(p), format!("split p = {p}"), RED);
    // A panel of `curves` (label, colour, values); in the range's ends
    // (dashed) if `marker` says where to mark it.
    let panel = |title: String, curves: &[(&str, RGBColor, &[f64])], marker: Option<_>| {
        let mut curves: Vec<Curve> = (curves.iter())
            .map(|&(label, color, values)| {
                let points = (0..).map(f64::from).zip(values.iter().copied());
                Curve::new(label, color, points.collect())
            })
            .collect();
        if marker.is_some() {
            let range = format!("[α1, α2] = [{a1}°, {a2}°]");
            for (label, y) in [(range, a1), (String::new(), a2)] {
                let points = vec![(0.0, y), ((n.max(2) - 1) as f64, y)];
                curves.push(Curve {
                    dashed: true,
                    ..Curve::new(label, GREY, points)
                });
            }
        }
        Panel {
            title,
            x_desc: "sample index n (generation order)".to_owned(),
            y_desc: "angle (°)".to_owned(),
            curves,
            markers: marker.into_iter().collect(),
            spans: Vec::new(),
        }
    };
    let mut panels = vec![
        panel(format!("1. {walk}"), &[("walk", GREY, &stages.walk)], None),
        panel(
            format!(
                "2. smoothed with a {}-tap Hann window ({window})",
                cfg.window
            ),
            &[
                ("walk", LIGHT, &stages.walk),
                ("smoothed", BLUE, &stages.smoothed),
            ],
            None,
        ),
        panel(
            "3. normalised into [α1, α2]".to_owned(),
            &[("normalised", ORANGE, &stages.normalized)],
            Some(split.clone()),
        ),
    ];
    if let Some((taper, tapered)) = &stages.tapered {
        let title = "4. Hann taper ½ − ½·cos(2πn/(N−1))".to_owned();
        let mut weights = panel(title, &[("taper", PURPLE, taper)], None);
        "weight".clone_into(&mut weights.y_desc);
        panels.push(weights);
        let title = "5. normalised × taper: both ends at zero".to_owned();
        panels.push(panel(title, &[("tapered", GREEN, tapered)], Some(split)));
    }
    let title = format!(
        "{}. final loop, stored (0.001° steps), in playback order: halves exchanged at p",
        panels.len() + 1
    );
    let start = (0.0, format!("start = sample p = {p}"), RED);
    let mut stored = panel(title, &[("final", RED, &stages.final_loop)], Some(start));
    "playback index i (final(i) = stage(i + p mod N))".clone_into(&mut stored.x_desc);
    let seam = (n - usize::from(p) % n) % n;
    if seam != 0 {
        let label = format!("seam: samples N−1 | 0 (index {seam})");
        stored.markers.push((seam as f64, label, GREY));
    }
    panels.push(stored);
    let note = "Idle-loop generation after Kocoń, section 3 (stages as in Figures 6 and 7)";
    let mut notes = vec![note.to_owned()];
    notes.extend(stages.metric_lines());
    let figure = Figure {
        title: stages.title(),
        notes,
        panels,
        panel_height: 240,
    };
    plot::draw(&figure, path)
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact values by construction
mod tests {
    use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N};

    use super::*;

    #[test]
    fn the_walks_normalisation_and_taper() {
        // The paper's walk steps by the top bit of r(n).
        let paper = walk(Closure::Paper, 127, 6, 0.5);
        let mut lcg = Lcg::new(127);
        assert_eq!(paper[0], 0.0);
        for i in 1..6 {
            let up = lcg.next_value() >= 1 << 31;
            let step = if up { 0.5 } else { -0.5 };
            assert_eq!(paper[i] - paper[i - 1], step);
        }
        // The seamless walk is periodic; its first step e(0) − D/N, e(0) from r(1).
        let looped = walk(Closure::Seamless, 8821, 900, 1.0);
        assert!(looped[899].abs() < 1e-9, "ends at zero: {}", looped[899]);
        assert!((looped[0] - f64::from(step_of(Lcg::new(8821).next_value()))).abs() < 1.0);
        assert_eq!(normalize(&[2.0, 4.0, 3.0], -4.0, 12.0), [-4.0, 12.0, 4.0]);
        assert_eq!(normalize(&[1.0, 1.0], -1.0, 1.0), [-1.0, -1.0]);
        let h = taper(5);
        assert!(h[0].abs() < 1e-12 && h[4].abs() < 1e-12 && (h[2] - 1.0).abs() < 1e-12);
        assert!((h[1] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn stages_of_a_default_axis() {
        for closure in [Closure::Paper, Closure::Seamless] {
            let cfg = DEFAULT_HEAD.pitch.with_closure(closure);
            let (axis, n) = (Axis::Pitch, DEFAULT_N);
            let stages = Stages::compute(LoopSpec { axis, n, cfg }).unwrap();
            let norm = stages.normalized.iter();
            let (lo, hi) = norm.fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
            assert!((lo + 4.0).abs() < 1e-9 && (hi - 12.0).abs() < 1e-9);
            assert_eq!(stages.tapered.is_some(), closure == Closure::Paper);
            let csv = stages.csv();
            assert_eq!(csv.lines().next(), Some("n,walk,smoothed,normalized,final"));
            assert_eq!(csv.lines().count(), DEFAULT_N + 1);
            assert!((mean(&stages.smoothed) - mean(&stages.walk)).abs() < 1e-9);
        }
    }
}
