//! A small text plot of the three axes' motion, from the frame lines of the
//! QEMU log.
//!
//! The log is the only record of the angles the firmware commanded (the
//! decoder hands out the formatted text, not the arguments), so the frame
//! lines are read back: `frame <n>: pitch=<deg> roll=<deg> yaw=<deg> deg, ...`.

// Frame counts and plot rows are small; the float conversions are exact.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]

use std::fmt::Write as _;

use crate::log::LogLine;

/// Columns of the plot.
const WIDTH: usize = 64;
/// Rows per axis.
const HEIGHT: usize = 7;
const AXES: [&str; 3] = ["pitch", "roll", "yaw"];

/// One frame line: its position on the time axis and the three angles.
struct Sample {
    /// The frame number.
    x: f64,
    angles: [f64; 3],
}

/// The plot, or `None` if the log has fewer than two frame lines.
pub fn plot(log: &[LogLine]) -> Option<String> {
    let mut samples: Vec<Sample> = log
        .iter()
        .filter_map(|line| frame_line(&line.message))
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

/// The frame number and the three angles of a frame line, if `message` is one.
fn frame_line(message: &str) -> Option<Sample> {
    let (frame, rest) = message.strip_prefix("frame ")?.split_once(": ")?;
    let mut words = rest.split_whitespace();
    let mut angles = [0.0; 3];
    for (angle, axis) in angles.iter_mut().zip(AXES) {
        let value = words.next()?.strip_prefix(axis)?.strip_prefix('=')?;
        *angle = value.parse().ok()?;
    }
    Some(Sample {
        x: frame.parse().ok()?,
        angles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_frame_lines_only() {
        let sample = frame_line(
            "frame 1650: pitch=-2.440 roll=+2.285 yaw=+7.611 deg, pulses 1473 1525 1585 us \
             (Written Written Failed(Other))",
        )
        .unwrap();
        assert_eq!((sample.x, sample.angles), (1650.0, [-2.44, 2.285, 7.611]));
        for other in [
            "frame 1400: join: the next loop set blends in over 100 frames",
            "frame 1650: injecting PWM write errors on yaw for 10 frames",
            "frame 7: pitch=+1.000 roll=+2.000 deg",
            "frame x: pitch=+1.000 roll=+2.000 yaw=+3.000 deg",
            "summary frames=1903 missed=0",
        ] {
            assert!(frame_line(other).is_none(), "{other}");
        }
    }

    #[test]
    fn plots_three_bands() {
        let log: Vec<LogLine> = (0..300)
            .map(|i| {
                let t = f64::from(i) / 300.0 * std::f64::consts::TAU;
                LogLine::new(
                    "INFO",
                    format!(
                        "frame {i}: pitch={:+.3} roll={:+.3} yaw={:+.3} deg",
                        4.0 * t.sin(),
                        2.0 * (2.0 * t).cos(),
                        9.0 * (t / 2.0).sin()
                    ),
                )
            })
            .collect();
        let plot = plot(&log).unwrap();
        println!("{plot}");
        let lines: Vec<&str> = plot.lines().collect();
        assert_eq!(lines.len(), 1 + 3 * HEIGHT);
        assert!(lines[0].contains("300 logged frames, frame 0 to 299"));
        // Each band is labelled with its axis and its extremes.
        assert!(lines[1].trim_start().starts_with("pitch") && lines[1].contains(" 4.0 |"));
        assert!(lines[HEIGHT].contains(" -4.0 |"));
        assert!(lines[1 + 2 * HEIGHT].trim_start().starts_with("yaw"));
    }
}
