//! `--pulses FILE.csv`: the pulses an emulator run measured on the servo
//! pins, one row per frame:
//!
//! ```text
//! t_ms,pitch_us,roll_us,yaw_us
//! ```
//!
//! Row `k` is frame `k`: the PWM period `k` from the first pulse on (the
//! neutral pulse of frame 0), at `t_ms = 20·k`. Each width is the pulse
//! that rose in that period, rising to falling edge, in µs (to 0.1 µs: a
//! count is 0.3125 µs), or 0 where the period had none (the pulses
//! stopped: a head relaxed at rest). The rows end with the last period
//! every servo's pulse is known for.
//!
//! [`measure`] gives a pin's complete pulses as measured, for the checks
//! that look at them (show control, the latency rows).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};

use super::pulses::{ServoCheck, Timing, Train};

/// One complete pulse on a pin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Rising edge, ns since power-on.
    pub rise: f64,
    /// Width, ns.
    pub width: f64,
}

/// The complete pulses of `train` (a rise and the fall after it), from the
/// slice's enable on.
pub fn measure(train: &Train) -> Vec<Measured> {
    let from = train.enabled.unwrap_or(f64::INFINITY);
    let mut rise = None;
    let mut out = Vec::new();
    for &(t, high) in train.edges.iter().filter(|&&(t, _)| t >= from) {
        match (high, rise) {
            (true, None) => rise = Some(t),
            (false, Some(r)) => {
                out.push(Measured {
                    rise: r,
                    width: t - r,
                });
                rise = None;
            }
            _ => {}
        }
    }
    out
}

/// Writes `servos`' pulses (`[pitch, roll, yaw]`, as checked) to `path`.
pub fn write(path: &Path, servos: &[ServoCheck; 3], timing: &Timing) -> Result<usize> {
    let text = rows(servos, timing);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    std::fs::write(path, &text).with_context(|| format!("writing {}", path.display()))?;
    Ok(text.lines().count() - 1)
}

/// The CSV's text.
#[allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)] // periods and counts, far below 2^52
fn rows(servos: &[ServoCheck; 3], timing: &Timing) -> String {
    let period = f64::from(timing.period_counts) * timing.count_ns;
    let first = servos
        .iter()
        .filter_map(|s| s.pulses.first().map(|p| p.rise))
        .fold(f64::INFINITY, f64::min);
    let mut widths: [Vec<Option<u32>>; 3] = Default::default();
    for (servo, out) in servos.iter().zip(&mut widths) {
        for pulse in &servo.pulses {
            let k = ((pulse.rise - first) / period).round().max(0.0) as usize;
            if out.len() <= k {
                out.resize(k + 1, None);
            }
            out[k] = Some(pulse.counts);
        }
    }
    let frames = widths.iter().map(Vec::len).min().unwrap_or(0);
    let us = |counts: Option<u32>| counts.map_or(0.0, |c| f64::from(c) * timing.count_ns / 1e3);
    let mut text = String::from("t_ms,pitch_us,roll_us,yaw_us\n");
    let [pitch, roll, yaw] = &widths;
    for (k, ((p, r), y)) in pitch.iter().zip(roll).zip(yaw).take(frames).enumerate() {
        let [p, r, y] = [*p, *r, *y].map(us);
        let _ = writeln!(text, "{},{p:.1},{r:.1},{y:.1}", k * 20);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::pulses::Pulse;

    #[test]
    fn a_row_per_period_and_0_where_there_was_no_pulse() {
        let timing = Timing {
            count_ns: 312.5,
            period_counts: 64_000,
            frame_ns: 20e6,
        };
        let pulse = |k: u32, counts| Pulse {
            rise: 1e6 + f64::from(k) * 20e6,
            counts,
            frame: k as usize,
        };
        let servo = |pulses: Vec<Pulse>| ServoCheck {
            pulses,
            ..ServoCheck::default()
        };
        let servos = [
            servo(vec![pulse(0, 4800), pulse(1, 4801), pulse(3, 4803)]),
            servo(vec![pulse(0, 4800), pulse(1, 4800), pulse(3, 4800)]),
            servo(vec![
                pulse(0, 4800),
                pulse(1, 4800),
                pulse(3, 4800),
                pulse(4, 1),
            ]),
        ];
        assert_eq!(
            rows(&servos, &timing),
            "t_ms,pitch_us,roll_us,yaw_us\n0,1500.0,1500.0,1500.0\n20,1500.3,1500.0,1500.0\n\
             40,0.0,0.0,0.0\n60,1500.9,1500.0,1500.0\n"
        );
    }
}
