//! The trace as a PNG: the three axes over time, each scripted command
//! marked where it was applied and its motion shaded on the axes it moves
//! (a look's return to the centre in blue, a refused command in red).

// Frame times are far below f64's exact range.
#![allow(clippy::cast_precision_loss)]

use std::path::Path;

use anyhow::Result;
use idle_head_core::Axis;
use plotters::style::RGBColor;

use super::Trace;
use super::marks::{Kind, Mark};
use crate::plot::{self, BLUE, Curve, Figure, GREEN, GREY, ORANGE, Panel, RED};

const SHADE: RGBColor = RGBColor(255, 228, 196);
const RETURN_SHADE: RGBColor = RGBColor(214, 230, 245);
const RETURN_MARK: RGBColor = RGBColor(70, 110, 160);

/// Draws `trace` to `path`; the time axis is in minutes past five of them.
pub fn draw(trace: &Trace, seed: Option<u32>, path: &Path) -> Result<()> {
    let end_s = trace.rows.last().map_or(0.0, |r| r.t_ms as f64 / 1000.0);
    let (unit, ms_per_unit) = if end_s > 300.0 {
        ("min", 60_000.0)
    } else {
        ("s", 1000.0)
    };
    let at = |ms: u64| ms as f64 / ms_per_unit;
    let color = |mark: &Mark| match mark.kind {
        _ if mark.refused() => RED,
        Kind::Return => RETURN_MARK,
        _ => GREY,
    };
    let panel = |axis: Axis, line: RGBColor| {
        let i = axis.index();
        let angles = trace
            .rows
            .iter()
            .map(|r| (at(r.t_ms), f64::from(r.angles[i]) / 1000.0));
        let on_axis = || trace.marks.iter().filter(move |m| m.axes.contains(&axis));
        let shade = |m: &Mark| {
            if m.kind == Kind::Return {
                RETURN_SHADE
            } else {
                SHADE
            }
        };
        Panel {
            title: format!("{} (°)", axis.name()),
            x_desc: format!("time ({unit})"),
            y_desc: "angle (°)".to_owned(),
            curves: vec![Curve::new(axis.name(), line, angles.collect())],
            spans: on_axis()
                .map(|m| (at(m.t_ms), at(m.t_ms + m.span_ms), shade(m)))
                .collect(),
            markers: trace
                .marks
                .iter()
                .filter(|m| m.axes.contains(&axis) || m.axes.is_empty())
                .map(|m| (at(m.t_ms), m.label.clone(), color(m)))
                .collect(),
        }
    };
    let loops = seed.map_or_else(
        || "Table 2 loops".to_owned(),
        |s| format!("loops of seed {s}"),
    );
    let figure = Figure {
        title: format!(
            "Commanded angles, {} frames of 20 ms ({loops}; after fade, limits and clamps)",
            trace.rows.len()
        ),
        notes: vec![
            "shaded: a command's motion on the axes it moves (blue: a look's return to the \
             centre); dashed: when it was applied (red: refused)"
                .to_owned(),
        ],
        panels: vec![
            panel(Axis::Pitch, BLUE),
            panel(Axis::Roll, ORANGE),
            panel(Axis::Yaw, GREEN),
        ],
        panel_height: 260,
    };
    plot::draw(&figure, path)
}
