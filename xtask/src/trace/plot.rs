//! The trace as a PNG: the three axes over time, each scripted command
//! marked where it was applied, its motion shaded on the axes it moves, and
//! a look's return to the centre shaded and marked too.
//!
//! A long trace has far more frames than the plot has pixel columns: then
//! each column shows the range of its frames (light) and their mean (a thin
//! line), the time axis is in minutes past five of them, and a label that
//! would cover another is left out (its dashed line stays).

// Frame counts, angles and pixel positions are far below f64's exact range.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_possible_wrap,
    clippy::cast_sign_loss
)]

use std::path::Path;

use anyhow::{Result, anyhow};
use idle_head_core::Axis;
use plotters::{coord::types::RangedCoordf64, prelude::*, style::FontStyle};

use super::marks::{Kind, Mark};
use super::{Row, Trace};
use crate::fonts::{self, FONT};

const WIDTH: u32 = 1400;
const HEADER: u32 = 70;
const PANEL: u32 = 260;
const BLUE: RGBColor = RGBColor(31, 119, 180);
const ORANGE: RGBColor = RGBColor(255, 127, 14);
const GREEN: RGBColor = RGBColor(44, 160, 44);
const GREY: RGBColor = RGBColor(110, 110, 110);
const SHADE: RGBColor = RGBColor(255, 228, 196);
const RETURN_SHADE: RGBColor = RGBColor(214, 230, 245);
const RETURN_MARK: RGBColor = RGBColor(70, 110, 160);
const REFUSED: RGBColor = RGBColor(214, 39, 40);
/// Label size, and the rows of labels at the top of a panel.
const LABEL_SIZE: u32 = 13;
const LABEL_ROWS: usize = 3;
/// A long trace's tick at the top of a panel: its share of the height, and
/// about as many pixels.
const TICK: f64 = 0.06;
const TICK_PIXELS: i32 = 12;
/// Pixels between a marker's line and its label.
const LABEL_GAP: i32 = 4;
/// Frames per pixel column above which a column shows a range and a mean.
const AGGREGATE_ABOVE: f64 = 2.0;
/// A panel's width that is not plot: the angle labels and the margins.
const MARGINS: u32 = 56 + 8 + 24 + 8;
/// Seconds above which the time axis is in minutes.
const MINUTES_ABOVE: f64 = 300.0;

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

/// The time axis: its unit and the trace's end in it.
#[derive(Clone, Copy)]
struct TimeAxis {
    /// Seconds per unit.
    seconds: f64,
    /// `s` or `min`.
    unit: &'static str,
    /// The trace's end, in units.
    end: f64,
}

impl TimeAxis {
    fn of(trace: &Trace) -> Self {
        let end_s = trace
            .rows
            .last()
            .map_or(1.0, |r| r.t_ms as f64 / 1000.0)
            .max(0.02);
        if end_s > MINUTES_ABOVE {
            Self {
                seconds: 60.0,
                unit: "min",
                end: end_s / 60.0,
            }
        } else {
            Self {
                seconds: 1.0,
                unit: "s",
                end: end_s,
            }
        }
    }

    /// `ms` in units.
    fn at(self, ms: u64) -> f64 {
        ms as f64 / 1000.0 / self.seconds
    }
}

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
    let time = TimeAxis::of(trace);
    header.draw(&Text::new(
        format!(
            "Commanded angles, {} frames of 20 ms ({loops}; after fade, limits and clamps)",
            trace.rows.len()
        ),
        (20, 14),
        (FONT, 22).into_font().style(FontStyle::Bold),
    ))?;
    let aggregated = trace.rows.len() as f64 / f64::from(WIDTH - MARGINS) > AGGREGATE_ABOVE;
    header.draw(&Text::new(
        format!(
            "shaded: a command's motion on the axes it moves (blue: a look's return to the \
             centre); {}: when it was applied (red: refused){}",
            if aggregated { "ticks" } else { "dashed" },
            if aggregated {
                "; each pixel column: its frames' range, light, and mean"
            } else {
                ""
            }
        ),
        (20, 44),
        (FONT, 15).into_font().color(&GREY),
    ))?;
    for ((area, axis), color) in body
        .split_evenly((3, 1))
        .iter()
        .zip(Axis::ALL)
        .zip([BLUE, ORANGE, GREEN])
    {
        panel(area, trace, axis, color, time)?;
    }
    Ok(())
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    trace: &Trace,
    axis: Axis,
    color: RGBColor,
    time: TimeAxis,
) -> DrawResult<()>
where
    DB::ErrorType: 'static,
{
    let i = axis.index();
    let (lo, hi) = trace
        .rows
        .iter()
        .map(|r| f64::from(r.angles[i]) / 1000.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo, hi)
    } else {
        (-1.0, 1.0)
    };
    // Room above the curves for the rows of labels.
    let pad = ((hi - lo) * 0.12).max(0.5);
    let (lo, hi) = (lo - pad, hi + 2.0 * pad);
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{} (°)", axis.name()),
            (FONT, 17).into_font().style(FontStyle::Bold),
        )
        .margin(8)
        .margin_right(24)
        .x_label_area_size(36)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..time.end, lo..hi)?;
    chart
        .configure_mesh()
        .x_desc(format!("time ({})", time.unit))
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 12))
        .x_label_formatter(&|x| format!("{x:.1}"))
        .y_label_formatter(&|y| format!("{y:.1}"))
        .max_light_lines(1)
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(218, 218, 218))
        .draw()?;
    for mark in trace.marks.iter().filter(|m| m.axes.contains(&axis)) {
        let shade = if mark.kind == Kind::Return {
            RETURN_SHADE
        } else {
            SHADE
        };
        chart.draw_series(std::iter::once(Rectangle::new(
            [
                (time.at(mark.t_ms), lo),
                (time.at(mark.t_ms + mark.span_ms), hi),
            ],
            shade.filled(),
        )))?;
    }
    let columns = chart.plotting_area().get_pixel_range().0.len().max(1);
    let aggregated = trace.rows.len() as f64 / columns as f64 > AGGREGATE_ABOVE;
    if aggregated {
        let bands = columns_of(&trace.rows, i, columns, time);
        let outline = bands
            .iter()
            .map(|b| (b.t, b.max))
            .chain(bands.iter().rev().map(|b| (b.t, b.min)));
        chart.draw_series(std::iter::once(Polygon::new(
            outline.collect::<Vec<_>>(),
            color.mix(0.3).filled(),
        )))?;
        chart.draw_series(LineSeries::new(
            bands.iter().map(|b| (b.t, b.mean)),
            color.stroke_width(1),
        ))?;
    } else {
        chart.draw_series(LineSeries::new(
            trace
                .rows
                .iter()
                .map(|r| (time.at(r.t_ms), f64::from(r.angles[i]) / 1000.0)),
            color.stroke_width(2),
        ))?;
    }
    markers(&mut chart, area, trace, (axis, aggregated), time, (lo, hi))
}

type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// When each mark was applied, and the labels of those on `axis`. In a
/// short trace a dashed line marks it across the panel; in a long one, a
/// tick at the top (a forest of lines would hide the curve), with two rows
/// of labels instead of three. A label goes right of its line, in the first
/// row where it covers no other label, on white; where there is none, it is
/// left out.
fn markers<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    area: &DrawingArea<DB, plotters::coord::Shift>,
    trace: &Trace,
    (axis, aggregated): (Axis, bool),
    time: TimeAxis,
    (lo, hi): (f64, f64),
) -> DrawResult<()>
where
    DB::ErrorType: 'static,
{
    let color = |mark: &Mark| match mark.kind {
        _ if mark.refused() => REFUSED,
        Kind::Return => RETURN_MARK,
        _ => GREY,
    };
    for mark in &trace.marks {
        let from = time.at(mark.t_ms);
        if aggregated {
            chart.draw_series(LineSeries::new(
                [(from, hi), (from, hi - (hi - lo) * TICK)],
                color(mark).stroke_width(1),
            ))?;
        } else {
            chart.draw_series(DashedLineSeries::new(
                [(from, lo), (from, hi)],
                5,
                4,
                color(mark).stroke_width(1),
            ))?;
        }
    }
    let font = (FONT, LABEL_SIZE).into_font();
    let measure = TextStyle::from(font.clone());
    // The right end of the last label in each row, in pixels.
    let mut rows = [i32::MIN; LABEL_ROWS];
    let rows = if aggregated {
        &mut rows[..2]
    } else {
        &mut rows[..]
    };
    // Below the ticks of a long trace.
    let top = if aggregated { TICK_PIXELS } else { 2 };
    for mark in &trace.marks {
        if !(mark.axes.contains(&axis) || mark.axes.is_empty()) {
            continue;
        }
        let from = time.at(mark.t_ms);
        let (x, _) = chart.backend_coord(&(from, hi));
        let (width, height) = area.estimate_text_size(&mark.label, &measure)?;
        let (width, height) = (width as i32, height as i32);
        let left = x + LABEL_GAP;
        let Some(row) = rows.iter().position(|&end| end < left) else {
            continue;
        };
        rows[row] = left + width + LABEL_GAP;
        let y = top + row as i32 * height;
        chart.plotting_area().draw(
            &(EmptyElement::at((from, hi))
                + Rectangle::new(
                    [(LABEL_GAP - 1, y), (LABEL_GAP + width + 1, y + height)],
                    WHITE.mix(0.85).filled(),
                )
                + Text::new(mark.label.clone(), (LABEL_GAP, y), font.color(&color(mark)))),
        )?;
    }
    Ok(())
}

/// One pixel column of a long trace.
struct Column {
    /// Its time, in the axis' unit.
    t: f64,
    /// The range of its frames' angles, and their mean, in degrees.
    min: f64,
    /// See `min`.
    max: f64,
    /// See `min`.
    mean: f64,
}

/// Axis `i` of `rows` in `columns` columns of equal time.
fn columns_of(rows: &[Row], i: usize, columns: usize, time: TimeAxis) -> Vec<Column> {
    let per = rows.len().div_ceil(columns).max(1);
    rows.chunks(per)
        .map(|chunk| {
            let degrees = chunk.iter().map(|r| f64::from(r.angles[i]) / 1000.0);
            let (min, max, sum) = degrees.fold(
                (f64::INFINITY, f64::NEG_INFINITY, 0.0),
                |(lo, hi, sum), v| (lo.min(v), hi.max(v), sum + v),
            );
            let middle = chunk[chunk.len() / 2].t_ms;
            Column {
                t: time.at(middle),
                min,
                max,
                mean: sum / chunk.len() as f64,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(frames: u64) -> Vec<Row> {
        (0..frames)
            .map(|frame| Row {
                frame,
                t_ms: frame * 20,
                t_us: frame * 20_000,
                period_us: 20_000,
                // A saw tooth of 10 frames: 0..9 °.
                angles: [i32::try_from(frame % 10).unwrap() * 1000; 3],
                pulses: [0; 3],
                duties: [0; 3],
            })
            .collect()
    }

    #[test]
    fn a_long_trace_is_shown_as_a_range_and_a_mean_per_column() {
        let rows = rows(180_000);
        let trace = Trace {
            rows: rows.clone(),
            marks: Vec::new(),
        };
        let time = TimeAxis::of(&trace);
        assert_eq!(time.unit, "min");
        assert!((time.end - 59.999_666).abs() < 1e-3, "{}", time.end);
        let columns = columns_of(&rows, 0, 1300, time);
        assert!(
            columns.len() <= 1300 && columns.len() > 1200,
            "{}",
            columns.len()
        );
        for column in &columns {
            assert!(
                (column.min, column.max) == (0.0, 9.0),
                "every column spans the tooth"
            );
            assert!((column.mean - 4.5).abs() < 0.1, "{}", column.mean);
        }
        assert!(columns.windows(2).all(|w| w[0].t < w[1].t));
        let short = Trace {
            rows: rows[..900].to_vec(),
            marks: Vec::new(),
        };
        assert_eq!(TimeAxis::of(&short).unit, "s");
    }
}
