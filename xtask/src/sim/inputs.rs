//! The trigger inputs' stage: a presence sensor on GP2 (a rest after 2 s,
//! relaxed, someone at 7 s); from the pulses, the rest, the pulses
//! stopping, the soft wake and the glance, every pulse the host trace's.

use std::path::Path;
use std::time::Duration;

use anyhow::{Context, Result};
use idle_head_core::Axis;
use idle_head_core::behaviour::{BehaviourConfig, LimitMode};

use super::pulses::{Pulse, angle};
use super::{run, script};
use crate::project::Metadata;
use crate::steps::Steps;
use crate::trace;

pub const INPUTS_STAGE: &str = "Pico image in the RP2040 emulator: a presence sensor rests, \
     relaxes, wakes softly and glances; every pulse the host trace's";

/// The script (times from the first frame).
pub const SCRIPT: &str = "\
0 input 2 presence -20000
0 rest after 2
0 rest relax on
7 pin 2 high
";

/// The stage: [`SCRIPT`] for 12.5 s (the glance from 8.1 s, and back).
pub fn test_inputs(root: &Path, metadata: &Metadata) -> Result<()> {
    let time = Duration::from_millis(12_500);
    let report = script::host(root, metadata, SCRIPT, time, script::Board::default())?;
    print!("{}", report.table());
    let boot = report.first()?;
    let timing = run::timing();
    let period = timing.period_ns();
    let pulses: [&Vec<Pulse>; 3] = [0, 1, 2].map(|i| &boot.servos[i].pulses);
    // The angle of a pulse on axis `i`, and a count of the servo clock
    // there (the rounding of a measured pulse), m°.
    let degrees = |i: usize, p: &Pulse| angle(i, f64::from(p.counts) * timing.count_ns);
    let count = |i: usize| angle(i, timing.count_ns) - angle(i, 0.0);
    let &(edge, _, _) = boot.drives.first().context("the harness drove no pin")?;
    // The gap: the longest stretch without a pulse on pitch.
    let gaps = pulses[0]
        .windows(2)
        .map(|w| (w[1].rise - w[0].rise, w[0], w[1]));
    let longest = gaps.reduce(|a, b| if b.0 > a.0 { b } else { a });
    let (span, before, after) = longest.context("no pulses")?;
    let us = |p: Pulse| f64::from(p.counts) * timing.count_ns / 1e3;
    println!(
        "pitch: last pulse before the gap {:.1} µs at {:.3} s, first after {:.1} µs at {:.3} s \
         ({:.1} s without pulses); GP2 high at {:.3} s",
        us(before),
        before.rise / 1e9,
        us(after),
        after.rise / 1e9,
        span / 1e9,
        edge / 1e9
    );
    let mut problems = Vec::new();
    // 1. Rested: at the rest pose when the pulses stopped (the glide had
    // arrived: its last frames there too), within a count.
    let rest = f64::from(BehaviourConfig::DEFAULT.rest.pose[0].millidegrees());
    let mut last = pulses[0]
        .iter()
        .filter(|p| p.rise <= before.rise && before.rise - p.rise < 2.5 * period);
    if !last.all(|p| (degrees(0, p) - rest).abs() <= count(0)) {
        let problem = "the head did not hold the rest pose (pitch 8°) before the pulses stopped";
        problems.push(problem.into());
    }
    // 2. Relaxed: seconds without pulses on every servo, ending after the
    // sensor's edge.
    if span < 1e9 || after.rise < edge {
        let gap = span / 1e9;
        problems.push(format!(
            "the pulses did not stop until the sensor's edge: the longest gap is {gap:.3} s"
        ));
    }
    for (i, name) in [(1, "roll"), (2, "yaw")] {
        let gap = before.rise + period / 2.0..after.rise - period / 2.0;
        if pulses[i].iter().any(|p| gap.contains(&p.rise)) {
            problems.push(format!("{name} had pulses while pitch had none"));
        }
    }
    // 3. The soft start: the first pulse after the gap is the last before
    // it, and the next second (the idle coming back) within the idle
    // limits, with a count of rounding each way.
    let (_, params) = trace::built_in()?;
    for axis in Axis::ALL {
        let (i, name) = (axis.index(), axis.name());
        let first = pulses[i].partition_point(|p| p.rise < after.rise - period / 2.0);
        if first == pulses[i].len() {
            problems.push(format!("{name}: no pulse after the gap"));
            continue;
        }
        let last_before = first.checked_sub(1).map(|k| pulses[i][k].counts);
        if last_before.is_none_or(|c| c.abs_diff(pulses[i][first].counts) > 1) {
            let problem = "the first pulse after the gap is not the last before it";
            problems.push(format!("{name}: {problem}"));
        }
        let wake: Vec<f64> = (pulses[i][first..].iter().take(50))
            .map(|p| degrees(i, p))
            .collect();
        let steps = Steps::of(&wake);
        let (step, turn) = (steps.step, steps.turn);
        println!(
            "{name}: waking, steps up to {step:.0} m° a frame, changes of step up to {turn:.0}"
        );
        let limits = Steps::allowed(&params, axis, LimitMode::Idle);
        let allowed = Steps {
            step: limits.step + count(i),
            turn: limits.turn + 2.0 * count(i),
        };
        if !steps.within(allowed) {
            problems.push(format!(
                "{name}: the wake exceeds the idle limits ({step:.0} m°/frame, {turn:.0} m°/frame²)"
            ));
        }
    }
    // 4. The glance: yaw at the sensor's −20° within 2.5° (the idle's sway)
    // after the wake, for about its 2 s hold.
    let near = (pulses[2].iter())
        .filter(|p| p.rise > after.rise && (degrees(2, p) + 20_000.0).abs() < 2_500.0)
        .count();
    println!("yaw: {near} pulses within 2.5° of the sensor's −20°");
    if near < 90 {
        problems.push(format!(
            "the head did not glance towards the sensor: {near} frames near −20°"
        ));
    }
    report.conclude(problems)
}
