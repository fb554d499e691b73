//! Every PNG of the project commands: stacked panels of curves, spans and
//! markers, drawn by plotters with a built-in font (the same on every
//! machine); a curve denser than its pixels as each column's range and mean.

// Sample counts and pixel positions are far below f64's exact range.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_possible_wrap,
    clippy::cast_sign_loss
)]

use std::{path::Path, sync::LazyLock};

use anyhow::{Result, anyhow, ensure};
use idle_head_core::Axis;
use plotters::{coord::Shift, prelude::*, style::FontStyle};

/// The family name the plots ask for; [`draw`] registers `DejaVu Sans` as it.
const FONT: &str = "sans-serif";
/// Pixels between a marker and its label.
const GAP: i32 = 4;

pub const BLUE: RGBColor = RGBColor(31, 119, 180);
pub const ORANGE: RGBColor = RGBColor(255, 127, 14);
pub const GREEN: RGBColor = RGBColor(44, 160, 44);
pub const RED: RGBColor = RGBColor(214, 39, 40);
pub const PURPLE: RGBColor = RGBColor(148, 103, 189);
pub const GREY: RGBColor = RGBColor(110, 110, 110);
pub const LIGHT: RGBColor = RGBColor(190, 190, 190);

/// A figure: a title, lines of text under it, and panels one above the
/// other, each `panel_height` pixels high.
pub struct Figure {
    pub title: String,
    pub notes: Vec<String>,
    pub panels: Vec<Panel>,
    pub panel_height: u32,
}

/// One panel: its curves over a shared x axis, shaded x ranges behind them
/// and dashed vertical markers with a label at the top.
pub struct Panel {
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub curves: Vec<Curve>,
    pub spans: Vec<(f64, f64, RGBColor)>,
    pub markers: Vec<(f64, String, RGBColor)>,
}

/// One curve (a dashed one is a reference line; one without a label has no
/// entry in the legend).
pub struct Curve {
    pub label: String,
    pub color: RGBColor,
    pub points: Vec<(f64, f64)>,
    pub dashed: bool,
}

impl Curve {
    /// A solid curve through `points`.
    pub fn new(label: impl Into<String>, color: RGBColor, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            color,
            points,
            dashed: false,
        }
    }
}

/// A command on the motion plot: from and to (x), the axes it shades (none:
/// only its marker, on every panel), its label and colours.
pub struct Mark {
    pub from: f64,
    pub to: f64,
    pub axes: Vec<Axis>,
    pub label: String,
    pub line: RGBColor,
    pub shade: RGBColor,
}

/// Draws the three axes' angles (°) over x (`rows`: x and the pitch, roll
/// and yaw angles) to `path`, each panel with the `marks` on its axis.
pub fn motion(
    path: &Path,
    title: String,
    notes: Vec<String>,
    x_desc: &str,
    rows: &[(f64, [f64; 3])],
    marks: &[Mark],
) -> Result<()> {
    let panel = |axis: Axis| {
        let i = axis.index();
        let points = rows.iter().map(|r| (r.0, r.1[i])).collect();
        let on = |m: &&Mark| m.axes.contains(&axis);
        let marked = |m: &&Mark| m.axes.is_empty() || m.axes.contains(&axis);
        Panel {
            title: format!("{} (°)", axis.name()),
            x_desc: x_desc.to_owned(),
            y_desc: "angle (°)".to_owned(),
            curves: vec![Curve::new(axis.name(), [BLUE, ORANGE, GREEN][i], points)],
            spans: (marks.iter().filter(on))
                .map(|m| (m.from, m.to, m.shade))
                .collect(),
            markers: (marks.iter().filter(marked))
                .map(|m| (m.from, m.label.clone(), m.line))
                .collect(),
        }
    };
    let figure = Figure {
        title,
        notes,
        panels: Axis::ALL.map(panel).into(),
        panel_height: 250,
    };
    draw(&figure, path)
}

/// Draws `figure` to the PNG `path`, creating its folder.
pub fn draw(figure: &Figure, path: &Path) -> Result<()> {
    static FONT_LOADED: LazyLock<bool> = LazyLock::new(|| {
        let styles = [
            (FontStyle::Normal, dejavu::sans::regular()),
            (FontStyle::Bold, dejavu::sans::bold()),
        ];
        let register = |(style, bytes)| plotters::style::register_font(FONT, style, bytes).is_ok();
        styles.into_iter().all(register)
    });
    ensure!(*FONT_LOADED, "the DejaVu Sans font did not load");
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    let header = 50 + 20 * u32::try_from(figure.notes.len())?;
    let height = header + figure.panel_height * u32::try_from(figure.panels.len())?;
    let root = BitMapBackend::new(path, (1400, height)).into_drawing_area();
    let fail = |e| anyhow!("drawing {}: {e}", path.display());
    paint(&root, figure, header).map_err(fail)?;
    root.present().map_err(|e| fail(e.into()))
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type Drawn = Result<(), Box<dyn std::error::Error>>;

fn paint(root: &Area<'_>, figure: &Figure, header: u32) -> Drawn {
    root.fill(&WHITE)?;
    let (top, body) = root.split_vertically(header);
    let title = (FONT, 22).into_font().style(FontStyle::Bold);
    top.draw(&Text::new(figure.title.clone(), (20, 14), title))?;
    for (i, note) in figure.notes.iter().enumerate() {
        let style = (FONT, 15).into_font().color(&GREY);
        top.draw(&Text::new(note.clone(), (20, 46 + 20 * i as i32), style))?;
    }
    let areas = body.split_evenly((figure.panels.len(), 1));
    for (area, panel) in areas.iter().zip(&figure.panels) {
        draw_panel(area, panel)?;
    }
    Ok(())
}

fn draw_panel(area: &Area<'_>, panel: &Panel) -> Drawn {
    let points = panel.curves.iter().flat_map(|c| c.points.iter());
    let (inf, neg) = (f64::INFINITY, f64::NEG_INFINITY);
    let (x0, x1, lo, hi) = points.fold((inf, neg, inf, neg), |(x0, x1, lo, hi), &(x, y)| {
        (x0.min(x), x1.max(x), lo.min(y), hi.max(y))
    });
    let (x0, x1) = if x1 > x0 { (x0, x1) } else { (0.0, 1.0) };
    let (lo, hi) = if hi >= lo { (lo, hi) } else { (-1.0, 1.0) };
    // Room above the curves for two rows of labels.
    let pad = ((hi - lo) * 0.1).max(0.5);
    let (lo, hi) = (lo - pad, hi + 2.5 * pad);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FONT, 17).into_font().style(FontStyle::Bold))
        .margin(8)
        .margin_right(24)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, lo..hi)?;
    chart
        .configure_mesh()
        .x_desc(&panel.x_desc)
        .y_desc(&panel.y_desc)
        .axis_desc_style((FONT, 14))
        .label_style((FONT, 13))
        .x_label_formatter(&|x| format!("{x:.1}"))
        .y_label_formatter(&|y| format!("{y:.1}"))
        .max_light_lines(1)
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(218, 218, 218))
        .draw()?;
    for &(from, to, color) in &panel.spans {
        chart.draw_series([Rectangle::new([(from, lo), (to, hi)], color.filled())])?;
    }
    let columns = chart.plotting_area().get_pixel_range().0.len().max(1);
    for curve in &panel.curves {
        let color = curve.color;
        let drawn = if curve.dashed {
            let line = DashedLineSeries::new(curve.points.clone(), 8, 6, color.stroke_width(1));
            chart.draw_series(line)?
        } else if curve.points.len() > 2 * columns {
            let bands = bands(&curve.points, columns);
            let outline = bands.iter().map(|b| (b.0, b.2));
            let outline = outline
                .chain(bands.iter().rev().map(|b| (b.0, b.1)))
                .collect::<Vec<_>>();
            chart.draw_series([Polygon::new(outline, color.mix(0.3).filled())])?;
            let mean = bands.iter().map(|b| (b.0, b.3));
            chart.draw_series(LineSeries::new(mean, color.stroke_width(1)))?
        } else {
            chart.draw_series(LineSeries::new(curve.points.clone(), color.stroke_width(2)))?
        };
        if !curve.label.is_empty() {
            let key = move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(3));
            drawn.label(&curve.label).legend(key);
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(GREY.mix(0.6))
        .draw()?;
    // Each marker's dashed line, and its label right of it in the first of
    // two rows at the top where it covers no other label (else left out).
    let font = (FONT, 13).into_font();
    let mut rows = [i32::MIN; 2];
    for (x, label, color) in &panel.markers {
        let line = [(*x, lo), (*x, hi)];
        chart.draw_series(DashedLineSeries::new(line, 5, 4, color.stroke_width(1)))?;
        let (width, height) = area.estimate_text_size(label, &TextStyle::from(font.clone()))?;
        let (width, height) = (width as i32, height as i32);
        let left = chart.backend_coord(&(*x, hi)).0 + GAP;
        let Some(row) = rows.iter().position(|&end| end < left) else {
            continue;
        };
        rows[row] = left + width + GAP;
        let y = 2 + row as i32 * height;
        let corners = [(GAP - 1, y), (GAP + width + 1, y + height)];
        let back = Rectangle::new(corners, WHITE.mix(0.85).filled());
        let text = Text::new(label.clone(), (GAP, y), font.color(color));
        chart
            .plotting_area()
            .draw(&(EmptyElement::at((*x, hi)) + back + text))?;
    }
    Ok(())
}

/// `points` in `columns` columns of as many points each: per column its
/// middle x, its lowest, highest and mean y.
fn bands(points: &[(f64, f64)], columns: usize) -> Vec<(f64, f64, f64, f64)> {
    let per = points.len().div_ceil(columns).max(1);
    let band = |chunk: &[(f64, f64)]| {
        let (min, max, sum) = chunk.iter().fold(
            (f64::INFINITY, f64::NEG_INFINITY, 0.0),
            |(lo, hi, sum), &(_, y)| (lo.min(y), hi.max(y), sum + y),
        );
        (chunk[chunk.len() / 2].0, min, max, sum / chunk.len() as f64)
    };
    points.chunks(per).map(band).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_curve_is_drawn_as_each_columns_range_and_mean_and_a_figure_is_drawn() {
        // A saw tooth of 10 points, 0 to 9, over 180,000 points.
        let saw = |i| (f64::from(i), f64::from(i % 10));
        let points: Vec<(f64, f64)> = (0..180_000).map(saw).collect();
        let bands = bands(&points, 1300);
        assert!(bands.len() <= 1300 && bands.len() > 1200, "{}", bands.len());
        for &(_, min, max, mean) in &bands {
            assert_eq!((min, max), (0.0, 9.0));
            assert!((mean - 4.5).abs() < 0.1, "{mean}");
        }
        assert!(bands.windows(2).all(|w| w[0].0 < w[1].0));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a/figure.png");
        let mark = Mark {
            from: 1.0,
            to: 2.0,
            axes: vec![Axis::Yaw],
            label: "here".into(),
            line: RED,
            shade: LIGHT,
        };
        let rows = [(0.0, [0.0; 3]), (1.0, [1.0, 2.0, 3.0]), (3.0, [0.0; 3])];
        let notes = vec!["a note".into()];
        motion(&path, "a figure".into(), notes, "s", &rows, &[mark]).unwrap();
        assert!(std::fs::read(&path).unwrap().starts_with(b"\x89PNG"));
    }
}
