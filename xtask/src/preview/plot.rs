//! The PNG of `cargo xtask preview`: the stages as stacked panels in the style
//! of the paper's Figures 6 and 7, the split point marked, and a text box with
//! the loop's metrics.

// Sample indices (< 2^13) and pixel positions are small: float conversions
// are exact or far below the plot's resolution.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss,
    clippy::cast_possible_wrap
)]

use std::path::Path;

use anyhow::{Result, anyhow};
use idle_head_core::motion::Closure;
use plotters::{
    coord::Shift,
    prelude::*,
    style::{
        FontStyle,
        text_anchor::{HPos, Pos, VPos},
    },
};

use super::stages::{LoopSpec, Stages, deg};
use crate::fonts::{self, FONT};

const WIDTH: u32 = 1400;
const HEADER: u32 = 150;
const PANEL: u32 = 240;
/// Width of the legend column right of each panel.
const LEGEND: u32 = 270;

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
    fonts::register()?;
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
