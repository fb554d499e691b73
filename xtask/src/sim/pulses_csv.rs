//! `--pulses FILE.csv`: the servo pulses of a run as measured on their pins
//! (GP16 pitch, GP18 roll, GP20 yaw), one row per PWM period:
//!
//! ```text
//! t_ms,pitch_us,roll_us,yaw_us
//! 20.001,1500.0,1500.0,1500.0
//! ```
//!
//! `t_ms` is when the pitch pulse rose (ms of virtual time since power-on),
//! each `_us` a pulse's width, rising edge to falling edge (µs, to 0.1 µs;
//! the PWM counts in steps of 0.3125 µs). Row `n` is the `n`-th complete
//! pulse of each servo: pulse `n` carries frame `n` (see `pulses.rs`).

use std::{fmt::Write as _, path::Path};

use anyhow::{Context, Result};

use super::pulses::Train;

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

/// Writes the pulses of `trains` (`[pitch, roll, yaw]`) to `path`; returns
/// the rows written.
pub fn write(path: &Path, trains: &[Train; 3]) -> Result<usize> {
    let [pitch, roll, yaw] = trains.each_ref().map(measure);
    let rows = pitch.len().min(roll.len()).min(yaw.len());
    let mut text = String::from("t_ms,pitch_us,roll_us,yaw_us\n");
    for ((p, r), y) in pitch.iter().zip(&roll).zip(&yaw).take(rows) {
        let _ = writeln!(
            text,
            "{:.3},{:.1},{:.1},{:.1}",
            p.rise / 1e6,
            p.width / 1e3,
            r.width / 1e3,
            y.width / 1e3
        );
    }
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_pair_the_servos_pulses_from_the_enable_on() {
        let train = |offset: f64, widths: &[f64]| {
            let mut edges = vec![(0.5e6, true), (0.6e6, false)]; // before the enable
            for (n, w) in (0_u32..).zip(widths) {
                let rise = 1e6 + offset + f64::from(n) * 20e6;
                edges.push((rise, true));
                edges.push((rise + w * 1e3, false));
            }
            edges.push((9e9, true)); // cut short: no fall
            Train {
                edges,
                enabled: Some(1e6),
                ..Train::default()
            }
        };
        let trains = [
            train(0.0, &[1500.0, 1512.5]),
            train(10.0, &[1500.0, 1490.3125]),
            train(20.0, &[1500.0, 1600.0, 1700.0]),
        ];
        let dir = std::env::temp_dir().join(format!("pulses-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("pulses.csv");
        assert_eq!(write(&path, &trains).unwrap(), 2);
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "t_ms,pitch_us,roll_us,yaw_us\n1.000,1500.0,1500.0,1500.0\n21.000,1512.5,1490.3,1600.0\n"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
