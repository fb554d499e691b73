//! `--pulses FILE.csv`: the pulses an emulator run measured on the servo
//! pins, one row per frame (`t_ms,pitch_us,roll_us,yaw_us`): row `k` is the
//! PWM period `k` from the first pulse on, each width the pulse that rose
//! in it (µs, to 0.1), or 0 where the period had none; `t_ms` has µs
//! decimals where the period has them (3.003·k at 333 Hz).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};

use super::pulses::{self, Timing, Train};

/// Writes the pulses on `trains`' pins (`[pitch, roll, yaw]`) to `path`;
/// the rows written.
pub fn write(path: &Path, trains: &[Train; 3], timing: &Timing) -> Result<usize> {
    let text = rows(trains, timing);
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
fn rows(trains: &[Train; 3], timing: &Timing) -> String {
    let period = f64::from(timing.period_counts) * timing.count_ns;
    let measured = trains.each_ref().map(pulses::measure);
    let first = measured
        .iter()
        .filter_map(|pulses| pulses.first().map(|p| p.rise))
        .fold(f64::INFINITY, f64::min);
    let mut widths: [Vec<Option<u32>>; 3] = Default::default();
    for (pulses, out) in measured.iter().zip(&mut widths) {
        for pulse in pulses {
            let k = ((pulse.rise - first) / period).round().max(0.0) as usize;
            if out.len() <= k {
                out.resize(k + 1, None);
            }
            // In whole counts, as the pulse check counts them.
            out[k] = Some((pulse.width / timing.count_ns).round().max(0.0) as u32);
        }
    }
    let frames = widths.iter().map(Vec::len).min().unwrap_or(0);
    let us = |counts: Option<u32>| counts.map_or(0.0, |c| f64::from(c) * timing.count_ns / 1e3);
    let mut text = String::from("t_ms,pitch_us,roll_us,yaw_us\n");
    let [pitch, roll, yaw] = &widths;
    let period_us = (timing.frame_ns / 1e3).round() as u64;
    for (k, ((p, r), y)) in pitch.iter().zip(roll).zip(yaw).take(frames).enumerate() {
        let [p, r, y] = [*p, *r, *y].map(us);
        let t_us = k as u64 * period_us;
        if t_us.is_multiple_of(1000) {
            let _ = write!(text, "{}", t_us / 1000);
        } else {
            let _ = write!(text, "{}.{:03}", t_us / 1000, t_us % 1000);
        }
        let _ = writeln!(text, ",{p:.1},{r:.1},{y:.1}");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    const TIMING: Timing = Timing {
        count_ns: 312.5,
        period_counts: 64_000,
        frame_ns: 20e6,
    };

    /// A pin's train as the emulator reports it, unchecked: pulse `k` of
    /// `counts` in period `k` (1 ms in), the slice enabled at 0.
    fn train(pulses: &[(u32, u32)]) -> Train {
        let mut edges = Vec::new();
        for &(k, counts) in pulses {
            let rise = 1e6 + f64::from(k) * 20e6;
            edges.push((rise, true));
            edges.push((rise + f64::from(counts) * TIMING.count_ns, false));
        }
        Train {
            edges,
            enabled: Some(0.0),
            ..Train::default()
        }
    }

    fn trains() -> [Train; 3] {
        [
            train(&[(0, 4800), (1, 4801), (3, 4803)]),
            train(&[(0, 4800), (1, 4800), (3, 4800)]),
            train(&[(0, 4800), (1, 4800), (3, 4800), (4, 1)]),
        ]
    }

    #[test]
    fn a_row_per_period_and_0_where_there_was_no_pulse() {
        assert_eq!(
            rows(&trains(), &TIMING),
            "t_ms,pitch_us,roll_us,yaw_us\n0,1500.0,1500.0,1500.0\n20,1500.3,1500.0,1500.0\n\
             40,0.0,0.0,0.0\n60,1500.9,1500.0,1500.0\n"
        );
    }

    /// At 333 Hz a row is 3003 µs after the one before.
    #[test]
    fn the_rows_are_a_period_apart_at_any_rate() {
        let timing = crate::sim::run::timing_at(idle_head_core::servo::ServoRate::MAX);
        let train = |k: u32| {
            let rise = 1e5 + f64::from(k) * timing.frame_ns;
            (rise, rise + 30_000.0 * timing.count_ns)
        };
        let trains = [(); 3].map(|()| Train {
            edges: (0..3)
                .flat_map(|k| {
                    let (rise, fall) = train(k);
                    [(rise, true), (fall, false)]
                })
                .collect(),
            enabled: Some(0.0),
            ..Train::default()
        });
        assert_eq!(
            rows(&trains, &timing),
            "t_ms,pitch_us,roll_us,yaw_us\n0,1500.0,1500.0,1500.0\n3.003,1500.0,1500.0,1500.0\n\
             6.006,1500.0,1500.0,1500.0\n"
        );
    }

    /// `--dmx` and `--show` runs check no pulse: the file comes from the
    /// edges of a boot as the run left it (once it came out a bare header).
    #[test]
    fn an_unchecked_boot_writes_its_rows() {
        let boot = crate::sim::run::Boot {
            trains: trains(),
            ..Default::default()
        };
        assert!(boot.servos.iter().all(|s| s.pulses.is_empty()));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out/pulses.csv");
        assert_eq!(write(&path, &boot.trains, &TIMING).unwrap(), 4);
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            rows(&boot.trains, &TIMING)
        );
    }
}
