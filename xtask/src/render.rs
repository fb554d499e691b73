//! A small text plot of the three axes' motion, read back from the QEMU log.
//!
//! Frame lines are recognised by their angles, written either as
//! `pitch=<n> roll=<n> yaw=<n>` (a unit may follow each number) or as a
//! bracketed triple after a word starting with `angle` (`angles=[p, r, y]`).

// Frame counts and plot rows are small; the float conversions are exact.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]

use std::fmt::Write as _;

/// Columns of the plot.
const WIDTH: usize = 64;
/// Rows per axis.
const HEIGHT: usize = 7;
const AXES: [&str; 3] = ["pitch", "roll", "yaw"];

/// One frame line: its position on the time axis and the three angles.
struct Sample {
    /// The frame number (`frame <n>`), or the line's place among the frame lines.
    x: f64,
    angles: [f64; 3],
}

/// The plot, or `None` if the log has fewer than two frame lines.
pub fn plot(log: &[crate::qemu::LogLine]) -> Option<String> {
    let mut samples: Vec<Sample> = log
        .iter()
        .filter_map(|line| angles(&line.message))
        .enumerate()
        .map(|(i, (frame, angles))| Sample {
            x: frame.unwrap_or(i as f64),
            angles,
        })
        .collect();
    samples.sort_by(|a, b| a.x.total_cmp(&b.x));
    let first = samples.first()?.x;
    let last = samples.last()?.x;
    if samples.len() < 2 || last <= first {
        return None;
    }
    // Each column shows the motion at its centre, interpolated between the
    // logged frames around it.
    let at = |x: f64, axis: usize| {
        let after = samples
            .partition_point(|sample| sample.x < x)
            .min(samples.len() - 1);
        let before = after.saturating_sub(1);
        let (a, b) = (&samples[before], &samples[after]);
        if b.x > a.x {
            a.angles[axis] + (b.angles[axis] - a.angles[axis]) * (x - a.x) / (b.x - a.x)
        } else {
            b.angles[axis]
        }
    };
    let centre = |column: usize| first + (last - first) * (column as f64 + 0.5) / WIDTH as f64;

    let mut out = String::new();
    let _ = writeln!(
        out,
        "motion: {} logged frames, frame {first} to {last} left to right, angles as logged",
        samples.len(),
    );
    for (axis, name) in AXES.iter().enumerate() {
        let columns: Vec<f64> = (0..WIDTH).map(|column| at(centre(column), axis)).collect();
        let min = columns.iter().copied().fold(f64::INFINITY, f64::min);
        let max = columns.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let span = if max > min { max - min } else { 1.0 };
        let row_of = |value: f64| {
            // Row 0 is the top (max), row HEIGHT-1 the bottom (min).
            let fraction = (max - value) / span;
            (fraction * (HEIGHT - 1) as f64).round() as usize
        };
        let zero_row = (min <= 0.0 && 0.0 <= max).then(|| row_of(0.0));
        for row in 0..HEIGHT {
            let label = match row {
                0 => format!("{name:<5} {max:>9.1}"),
                r if r == HEIGHT - 1 => format!("{:<5} {min:>9.1}", ""),
                _ => String::new(),
            };
            let line: String = columns
                .iter()
                .map(|&value| {
                    if row_of(value) == row {
                        '*'
                    } else if zero_row == Some(row) {
                        '-'
                    } else {
                        ' '
                    }
                })
                .collect();
            let _ = writeln!(out, "{label:>15} |{line}|");
        }
    }
    Some(out)
}

/// The frame number (if given as `frame <n>`) and the three angles of a
/// frame line, if `message` is one.
fn angles(message: &str) -> Option<(Option<f64>, [f64; 3])> {
    let angles = keyed(message).or_else(|| bracketed(message))?;
    let frame = message
        .split_once("frame ")
        .and_then(|(_, rest)| leading_number(rest));
    Some((frame, angles))
}

fn keyed(message: &str) -> Option<[f64; 3]> {
    let mut found = [None; 3];
    for token in message.split(|c: char| c.is_whitespace() || c == ',') {
        let Some((key, value)) = token.split_once(['=', ':']) else {
            continue;
        };
        if let Some(axis) = AXES.iter().position(|name| key.eq_ignore_ascii_case(name)) {
            found[axis] = leading_number(value);
        }
    }
    Some([found[0]?, found[1]?, found[2]?])
}

fn bracketed(message: &str) -> Option<[f64; 3]> {
    let at = message.find("angle")?;
    let rest = &message[at..];
    let open = rest.find('[')?;
    let close = rest[open..].find(']')? + open;
    let values: Vec<f64> = rest[open + 1..close]
        .split(',')
        .map(|value| leading_number(value.trim()))
        .collect::<Option<_>>()?;
    <[f64; 3]>::try_from(values).ok()
}

/// The number at the start of `text` (`-12`, `3.5`, `+7mdeg` -> 7).
fn leading_number(text: &str) -> Option<f64> {
    let end = text
        .char_indices()
        .find(|&(i, c)| !(c.is_ascii_digit() || c == '.' || (i == 0 && (c == '-' || c == '+'))))
        .map_or(text.len(), |(i, _)| i);
    text[..end].parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::qemu::LogLine;

    #[test]
    fn reads_keyed_and_bracketed_angles() {
        assert_eq!(
            angles("frame 3 pitch=-120 roll=45mdeg yaw=+7 pulses=[1500, 1490, 1510]"),
            Some((Some(3.0), [-120.0, 45.0, 7.0]))
        );
        assert_eq!(
            angles("angles=[1.5, -2, 3] pulses=[1500, 1490, 1510]"),
            Some((None, [1.5, -2.0, 3.0]))
        );
        assert_eq!(angles("summary missed=0"), None);
    }

    #[test]
    fn plots_three_bands() {
        let log: Vec<LogLine> = (0..300)
            .map(|i| {
                let t = f64::from(i) / 300.0 * std::f64::consts::TAU;
                LogLine {
                    level: Some("INFO".to_owned()),
                    message: format!(
                        "frame {i} pitch={:.0} roll={:.0} yaw={:.0}",
                        4000.0 * t.sin(),
                        2000.0 * (2.0 * t).cos(),
                        9000.0 * (t / 2.0).sin()
                    ),
                    timestamp: None,
                    location: None,
                }
            })
            .collect();
        let plot = plot(&log).unwrap();
        println!("{plot}");
        assert_eq!(plot.lines().count(), 1 + 3 * HEIGHT);
    }
}
