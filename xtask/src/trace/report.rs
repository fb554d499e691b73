//! A trace's CSV and the summary printed with it.

use std::fs;

use anyhow::{Context, Result};
use idle_head_core::Axis;

use super::Trace;
use crate::steps::Steps;

/// Writes `trace` as CSV to `path` (a row per frame).
pub fn write_csv(trace: &Trace, path: &std::path::Path) -> Result<()> {
    use std::fmt::Write as _;
    let mut csv =
        String::from("frame,t_ms,pitch_mdeg,roll_mdeg,yaw_mdeg,pitch_ns,roll_ns,yaw_ns\n");
    for row in &trace.rows {
        let [p, r, y] = row.angles;
        let [pn, rn, yn] = row.pulses;
        let t_ms = match row.t_us % 1000 {
            0 => format!("{}", row.t_us / 1000),
            us => format!("{}.{us:03}", row.t_us / 1000),
        };
        let _ = writeln!(csv, "{},{t_ms},{p},{r},{y},{pn},{rn},{yn}", row.frame);
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    fs::write(path, csv).with_context(|| format!("writing {}", path.display()))
}

/// Prints the range, largest step and largest change of step per axis.
pub fn summary(trace: &Trace) {
    for (i, axis) in Axis::ALL.iter().enumerate() {
        let values: Vec<i64> = trace.rows.iter().map(|r| i64::from(r.angles[i])).collect();
        let (lo, hi) = values
            .iter()
            .fold((i64::MAX, i64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let angles: Vec<f64> = trace.rows.iter().map(|r| f64::from(r.angles[i])).collect();
        let Steps { step, turn } = Steps::of(&angles);
        let pulses = trace.rows.iter().map(|r| r.pulses[i]);
        let (plo, phi) = pulses.fold((u64::MAX, 0), |(lo, hi), p| (lo.min(p), hi.max(p)));
        println!(
            "{:<5} angle {lo}..{hi} mdeg, largest step {step:.0} mdeg/frame, largest change of step {turn:.0} mdeg/frame² (frames as they came), pulses {plo}..{phi} ns",
            axis.name()
        );
    }
}
