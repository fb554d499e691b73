//! The trace as a PNG: the three axes over time, each scripted command
//! marked where it was applied, its motion shaded on the axes it moves.

// Frame counts and angles are far below f64's exact range.
#![allow(clippy::cast_precision_loss)]

use std::path::Path;

use anyhow::{Result, anyhow};
use idle_head_core::Axis;
use plotters::{prelude::*, style::FontStyle};

use super::{Mark, Trace};
use crate::fonts::{self, FONT};

const WIDTH: u32 = 1400;
const HEADER: u32 = 70;
const PANEL: u32 = 260;
const BLUE: RGBColor = RGBColor(31, 119, 180);
const ORANGE: RGBColor = RGBColor(255, 127, 14);
const GREEN: RGBColor = RGBColor(44, 160, 44);
const GREY: RGBColor = RGBColor(110, 110, 110);
const SHADE: RGBColor = RGBColor(255, 228, 196);
const REFUSED: RGBColor = RGBColor(214, 39, 40);

/// Draws `trace` to `path`.
pub fn draw(trace: &Trace, seed: Option<u32>, path: &Path) -> Result<()> {
    fonts::register()?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    let root = BitMapBackend::new(path, (WIDTH, HEADER + 3 * PANEL)).into_drawing_area();
    paint(&root, trace, seed).map_err(|e| anyhow!("drawing {}: {e}", path.display()))?;
    root.present()
        .map_err(|e| anyhow!("writing {}: {e}", path.display()))?;
    Ok(())
}

type DrawResult<T> = Result<T, Box<dyn std::error::Error>>;

fn paint<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    trace: &Trace,
    seed: Option<u32>,
) -> DrawResult<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (header, body) = root.split_vertically(HEADER);
    let loops = seed.map_or_else(
        || "Table 2 loops".to_owned(),
        |s| format!("loops of seed {s}"),
    );
    header.draw(&Text::new(
        format!(
            "Commanded angles, {} frames of 20 ms ({loops}; after fade, limits and clamps)",
            trace.rows.len()
        ),
        (20, 14),
        (FONT, 22).into_font().style(FontStyle::Bold),
    ))?;
    header.draw(&Text::new(
        "shaded: a command's motion on the axes it moves; dashed: when it was applied (red: refused)",
        (20, 44),
        (FONT, 15).into_font().color(&GREY),
    ))?;
    let end_s = trace
        .rows
        .last()
        .map_or(1.0, |r| r.t_ms as f64 / 1000.0)
        .max(0.02);
    for ((area, axis), color) in body
        .split_evenly((3, 1))
        .iter()
        .zip(Axis::ALL)
        .zip([BLUE, ORANGE, GREEN])
    {
        panel(area, trace, axis, color, end_s)?;
    }
    Ok(())
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    trace: &Trace,
    axis: Axis,
    color: RGBColor,
    end_s: f64,
) -> DrawResult<()>
where
    DB::ErrorType: 'static,
{
    let i = axis.index();
    let degrees: Vec<(f64, f64)> = trace
        .rows
        .iter()
        .map(|r| (r.t_ms as f64 / 1000.0, f64::from(r.angles[i]) / 1000.0))
        .collect();
    let (lo, hi) = degrees
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(_, v)| {
            (lo.min(v), hi.max(v))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo, hi)
    } else {
        (-1.0, 1.0)
    };
    let pad = ((hi - lo) * 0.12).max(0.5);
    let (lo, hi) = (lo - pad, hi + pad);
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{} (°)", axis.name()),
            (FONT, 17).into_font().style(FontStyle::Bold),
        )
        .margin(8)
        .margin_right(24)
        .x_label_area_size(36)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..end_s, lo..hi)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 12))
        .x_label_formatter(&|x| format!("{x:.1}"))
        .y_label_formatter(&|y| format!("{y:.1}"))
        .max_light_lines(1)
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(218, 218, 218))
        .draw()?;
    for mark in trace.marks.iter().filter(|m| m.axes.contains(&axis)) {
        let (from, to) = span(mark);
        chart.draw_series(std::iter::once(Rectangle::new(
            [(from, lo), (to, hi)],
            SHADE.filled(),
        )))?;
    }
    chart.draw_series(LineSeries::new(degrees, color.stroke_width(2)))?;
    for mark in &trace.marks {
        let (from, _) = span(mark);
        let refused = mark.reply.starts_with("err");
        let line = if refused { REFUSED } else { GREY };
        chart.draw_series(DashedLineSeries::new(
            [(from, lo), (from, hi)],
            5,
            4,
            line.stroke_width(1),
        ))?;
        if mark.axes.contains(&axis) || mark.axes.is_empty() {
            chart.draw_series(std::iter::once(Text::new(
                mark.label.clone(),
                (from, hi),
                (FONT, 13).into_font().color(&line),
            )))?;
        }
    }
    Ok(())
}

/// A mark's start and end in seconds.
fn span(mark: &Mark) -> (f64, f64) {
    let from = mark.t_ms as f64 / 1000.0;
    (from, from + mark.span_ms as f64 / 1000.0)
}
