//! The figure of `cargo xtask preview`: a loop's stages as stacked panels
//! (drawn by [`crate::plot`]).

// Sample indices are far below f64's exact range.
#![allow(clippy::cast_precision_loss)]

use std::path::Path;

use anyhow::Result;
use idle_head_core::motion::Closure;
use plotters::style::RGBColor;

use super::stages::{Stages, deg};
use crate::plot::{self, BLUE, Curve, Figure, GREEN, GREY, LIGHT, ORANGE, PURPLE, Panel, RED};

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
            .map(|&(label, color, values)| Curve::indexed(label, color, values))
            .collect();
        let range = format!("[α1, α2] = [{a1}°, {a2}°]");
        for (label, y) in marker
            .iter()
            .flat_map(|_| [(range.clone(), a1), (String::new(), a2)])
        {
            let points = vec![(0.0, y), ((n.max(2) - 1) as f64, y)];
            curves.push(Curve {
                dashed: true,
                ..Curve::new(label, GREY, points)
            });
        }
        let x_desc = "sample index n (generation order)".to_owned();
        let y_desc = "angle (°)".to_owned();
        let markers = marker.into_iter().collect();
        Panel {
            title,
            x_desc,
            y_desc,
            curves,
            markers,
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
