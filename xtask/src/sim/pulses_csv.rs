//! `--pulses FILE.csv`: row `k` (`t_ms,pitch_us,roll_us,yaw_us`) is PWM
//! period `k` from the first pulse, each width the pulse that rose in it
//! (0 for none).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;

use super::pulses::{self, Timing, Train};

/// Writes `trains`' pulses to `path` and says how many rows.
pub fn write(path: &Path, trains: &[Train; 3], timing: &Timing) -> Result<()> {
    let text = rows(trains, timing);
    crate::project::write(path, &text)?;
    let rows = text.lines().count() - 1;
    println!("wrote {} ({rows} frames)", path.display());
    Ok(())
}

#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // a period index and µs, far below 2^52
fn rows(trains: &[Train; 3], timing: &Timing) -> String {
    let period = timing.period_ns();
    let measured = trains.each_ref().map(pulses::measure);
    let starts = measured
        .iter()
        .filter_map(|pulses| pulses.first().map(|p| p.rise));
    let first = starts.fold(f64::INFINITY, f64::min);
    let widths = measured.map(|pulses| {
        let mut us = Vec::new();
        for pulse in pulses {
            let k = ((pulse.rise - first) / period).round().max(0.0) as usize;
            us.resize(us.len().max(k + 1), 0.0);
            // In whole counts, as the pulse check counts them.
            us[k] = (pulse.width / timing.count_ns).round().max(0.0) * timing.count_ns / 1e3;
        }
        us
    });
    let period_us = (timing.frame_ns / 1e3).round() as u64;
    let mut text = String::from("t_ms,pitch_us,roll_us,yaw_us\n");
    let [pitch, roll, yaw] = &widths;
    // As many rows as the shortest servo's periods (`zip` stops there).
    for (k, ((p, r), y)) in pitch.iter().zip(roll).zip(yaw).enumerate() {
        let t = crate::trace::ms(k as u64 * period_us);
        let _ = writeln!(text, "{t},{p:.1},{r:.1},{y:.1}");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Trains as the emulator reports them, unchecked: pulse `k` of
    /// `counts` in period `k` (at `t0` + k periods), the slice enabled at 0.
    fn make(pulses: [&[(u32, u32)]; 3], timing: &Timing, t0: f64) -> [Train; 3] {
        pulses.map(|pulses| {
            let edges = pulses.iter().flat_map(|&(k, counts)| {
                let rise = t0 + f64::from(k) * timing.frame_ns;
                let fall = rise + f64::from(counts) * timing.count_ns;
                [(rise, true), (fall, false)]
            });
            Train {
                edges: edges.collect(),
                enabled: Some(0.0),
                ..Train::default()
            }
        })
    }

    #[test]
    fn a_row_per_period_a_period_apart_at_any_rate_and_0_where_there_was_no_pulse() {
        let timing = crate::sim::run::timing();
        let neutral: &[(u32, u32)] = &[(0, 4800), (1, 4800), (3, 4800)];
        let pitch: &[(u32, u32)] = &[(0, 4800), (1, 4801), (3, 4803)];
        let trains = make([pitch, neutral, neutral], &timing, 1e6);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out/pulses.csv");
        write(&path, &trains, &timing).unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "t_ms,pitch_us,roll_us,yaw_us\n0,1500.0,1500.0,1500.0\n20,1500.3,1500.0,1500.0\n\
             40,0.0,0.0,0.0\n60,1500.9,1500.0,1500.0\n"
        );
        // At 333 Hz a row is 3003 µs after the one before.
        let timing = crate::sim::run::timing_at(idle_head_core::servo::ServoRate::MAX);
        let pulses: &[(u32, u32)] = &[(0, 30_000), (1, 30_000)];
        let rows = rows(&make([pulses; 3], &timing, 1e5), &timing);
        assert_eq!(
            rows,
            "t_ms,pitch_us,roll_us,yaw_us\n0,1500.0,1500.0,1500.0\n3.003,1500.0,1500.0,1500.0\n"
        );
    }
}
