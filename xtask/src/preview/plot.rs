//! The PNG of `cargo xtask preview`: the stages as stacked panels in the
//! style of the paper's Figures 6 and 7, the split point marked, and the
//! loop's metrics.

// Sample indices are far below f64's exact range.
#![allow(clippy::cast_precision_loss)]

use std::path::Path;

use anyhow::Result;
use idle_head_core::motion::Closure;

use super::stages::{LoopSpec, Stages, deg};
use crate::plot::{self, BLUE, Curve, Figure, GREEN, GREY, LIGHT, ORANGE, PURPLE, Panel, RED};

/// Draws the figure to `path` (PNG).
pub fn plot(stages: &Stages, path: &Path) -> Result<()> {
    let LoopSpec { n, cfg, .. } = stages.spec;
    let (a1, a2) = (deg(cfg.range.min), deg(cfg.range.max));
    let p = usize::from(stages.info.split);
    let last = (n.max(2) - 1) as f64;
    let panel = |title: String, curves: Vec<Curve>| Panel {
        title,
        x_desc: "sample index n (generation order)".to_owned(),
        y_desc: "angle (°)".to_owned(),
        curves,
        ..Panel::default()
    };
    // The range's ends, dashed, and the split point.
    let in_range = |mut panel: Panel| {
        for (label, level) in [
            (format!("[α1, α2] = [{a1}°, {a2}°]"), a1),
            (String::new(), a2),
        ] {
            let points = vec![(0.0, level), (last, level)];
            let dashed = true;
            panel.curves.push(Curve {
                label,
                color: GREY,
                points,
                dashed,
            });
        }
        panel
    };
    let split = |mut panel: Panel| {
        panel
            .markers
            .push((p as f64, format!("split p = {p}"), RED));
        panel
    };
    let mut panels = vec![
        panel(
            match cfg.closure {
                Closure::Paper => "1. random walk u(n) = u(n−1) ± δ".to_owned(),
                Closure::Seamless => "1. periodic random walk (mean step removed)".to_owned(),
            },
            vec![Curve::indexed("walk", GREY, &stages.walk)],
        ),
        panel(
            format!(
                "2. smoothed with a {}-tap Hann window ({})",
                cfg.window,
                match cfg.closure {
                    Closure::Paper => "causal",
                    Closure::Seamless => "circular",
                }
            ),
            vec![
                Curve::indexed("walk", LIGHT, &stages.walk),
                Curve::indexed("smoothed", BLUE, &stages.smoothed),
            ],
        ),
        split(in_range(panel(
            "3. normalised into [α1, α2]".to_owned(),
            vec![Curve::indexed("normalised", ORANGE, &stages.normalized)],
        ))),
    ];
    if let Some((taper, tapered)) = &stages.tapered {
        let mut weights = panel(
            "4. Hann taper ½ − ½·cos(2πn/(N−1))".to_owned(),
            vec![Curve::indexed("taper", PURPLE, taper)],
        );
        "weight".clone_into(&mut weights.y_desc);
        panels.push(weights);
        panels.push(split(in_range(panel(
            "5. normalised × taper: both ends at zero".to_owned(),
            vec![Curve::indexed("tapered", GREEN, tapered)],
        ))));
    }
    let mut stored = in_range(panel(
        format!(
            "{}. final loop, stored (0.001° steps), in playback order: halves exchanged at p",
            panels.len() + 1
        ),
        vec![Curve::indexed("final", RED, &stages.final_loop)],
    ));
    "playback index i (final(i) = stage(i + p mod N))".clone_into(&mut stored.x_desc);
    stored
        .markers
        .push((0.0, format!("start = sample p = {p}"), RED));
    let seam = (n - p % n) % n;
    if seam != 0 {
        let label = format!("seam: samples N−1 | 0 (index {seam})");
        stored.markers.push((seam as f64, label, GREY));
    }
    panels.push(stored);
    let mut notes = vec![
        "Idle-loop generation after Kocoń, section 3 (stages as in Figures 6 and 7)".to_owned(),
    ];
    notes.extend(stages.metric_lines());
    let figure = Figure {
        title: stages.title(),
        notes,
        panels,
        panel_height: 240,
    };
    plot::draw(&figure, path)
}
