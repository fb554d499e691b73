//! The trigger inputs' stage: a presence script (a sensor on GP2, a rest
//! after 2 s with relax on, someone at 7 s) played into the shipped image;
//! from the pulses, the rest, the pulses stopping, the soft wake and the
//! glance towards the sensor, every pulse the host trace's duty.

use std::path::Path;
use std::time::Duration;

use anyhow::{Result, bail};
use idle_head_core::Axis;
use idle_head_core::behaviour::{BehaviourConfig, BehaviourParams, LimitMode};

use super::pulses::{Pulse, angle};
use super::run;
use super::script;
use crate::project::Metadata;
use crate::steps::Steps;
use crate::trace;

/// The stage's name.
pub const INPUTS_STAGE: &str = "Pico image in the RP2040 emulator: a presence sensor rests, \
     relaxes, wakes softly and glances; every pulse the host trace's";

/// The script (times from the first frame).
pub const SCRIPT: &str = "\
0 input 2 presence -20000
0 rest after 2
0 rest relax on
7 pin 2 high
";

/// How long it runs: the glance (from about 8.1 s) held and back.
const TIME: Duration = Duration::from_millis(12_500);

/// Where the sensor looks from ([`SCRIPT`]'s `presence -20000`), m°.
const SENSOR_YAW: f64 = -20_000.0;

/// `cargo xtask test`'s stage: plays [`SCRIPT`] and checks it.
pub fn test_inputs(root: &Path, metadata: &Metadata) -> Result<()> {
    let events = script::parse(SCRIPT)?;
    let report = script::play(
        root,
        metadata,
        events,
        TIME,
        super::WALL,
        script::Against::Host,
    )?;
    print!("{}", report.table());
    println!("{}", report.verdict());
    let mut problems = report.problems.clone();
    let Some(boot) = report.boots.first() else {
        bail!("no boot");
    };
    let timing = run::timing();
    let period = f64::from(timing.period_counts) * timing.count_ns;
    let pulses: [&Vec<Pulse>; 3] = [0, 1, 2].map(|i| &boot.servos[i].pulses);
    let Some(&(edge, _, _)) = boot.drives.first() else {
        bail!("the harness drove no pin");
    };
    // The gap: the longest stretch without a pulse on pitch.
    let gap = pulses[0]
        .windows(2)
        .map(|w| (w[1].rise - w[0].rise, w[0], w[1]))
        .fold(None, |best: Option<(f64, Pulse, Pulse)>, x| match best {
            Some(b) if b.0 >= x.0 => Some(b),
            _ => Some(x),
        });
    let Some((span, before, after)) = gap else {
        bail!("no pulses");
    };
    let ms = |ns: f64| ns / 1e6;
    println!(
        "pitch: last pulse before the gap {:.1} µs at {:.3} s, first after {:.1} µs at {:.3} s \
         ({:.1} s without pulses); GP2 high at {:.3} s",
        f64::from(before.counts) * timing.count_ns / 1e3,
        ms(before.rise) / 1e3,
        f64::from(after.counts) * timing.count_ns / 1e3,
        ms(after.rise) / 1e3,
        ms(span) / 1e3,
        ms(edge) / 1e3
    );
    // 1. Rested: at the rest pose when the pulses stopped (the glide had
    // arrived: its last frames there too), within a count.
    let rest = f64::from(BehaviourConfig::DEFAULT.rest.pose[0].millidegrees());
    let held = pulses[0]
        .iter()
        .filter(|p| p.rise <= before.rise && before.rise - p.rise < 2.5 * period)
        .all(|p| (degrees(0, p) - rest).abs() <= count(0));
    if !held {
        problems.push(
            "the head did not hold the rest pose (pitch 8°) before the pulses stopped".into(),
        );
    }
    // 2. Relaxed: seconds without pulses on every servo, ending after the
    // sensor's edge.
    if span < 1e9 || after.rise < edge {
        problems.push(format!(
            "the pulses did not stop until the sensor's edge: the longest gap is {:.3} s",
            ms(span) / 1e3
        ));
    }
    for (i, name) in ["roll", "yaw"].iter().enumerate() {
        let inside = pulses[i + 1]
            .iter()
            .any(|p| p.rise > before.rise + period / 2.0 && p.rise < after.rise - period / 2.0);
        if inside {
            problems.push(format!("{name} had pulses while pitch had none"));
        }
    }
    let (_, params) = trace::built_in()?;
    soft_start(&pulses, after.rise, period, &params, &mut problems);
    let yaw = pulses[2].iter().map(|p| (p.rise, degrees(2, p)));
    glance(yaw, after.rise, &mut problems);
    if problems.is_empty() {
        println!(
            "inputs: ok: rested, relaxed {:.1} s, woke softly from the pose, glanced towards the sensor",
            ms(span) / 1e3
        );
        Ok(())
    } else {
        bail!("{}", problems.join("\n"))
    }
}

/// The soft start (check 3): the first pulse after the gap (at `after`) is
/// the last before it, and the next second (the idle coming back) within
/// the idle limits, with a count of rounding each way.
fn soft_start(
    pulses: &[&Vec<Pulse>; 3],
    after: f64,
    period: f64,
    params: &BehaviourParams,
    problems: &mut Vec<String>,
) {
    for axis in Axis::ALL {
        let (i, name) = (axis.index(), axis.name());
        let first = pulses[i]
            .iter()
            .position(|p| p.rise >= after - period / 2.0);
        let Some(first) = first else {
            problems.push(format!("{name}: no pulse after the gap"));
            continue;
        };
        let last_before = first.checked_sub(1).map(|k| pulses[i][k].counts);
        if last_before.is_none_or(|c| c.abs_diff(pulses[i][first].counts) > 1) {
            problems.push(format!(
                "{name}: the first pulse after the gap is not the last before it"
            ));
        }
        let wake: Vec<f64> = pulses[i][first..]
            .iter()
            .take(50)
            .map(|p| degrees(i, p))
            .collect();
        let steps = Steps::of(&wake);
        println!(
            "{name}: waking, steps up to {:.0} m° a frame, changes of step up to {:.0}",
            steps.step, steps.turn
        );
        // A count of rounding each way.
        let limits = Steps::allowed(params, axis, LimitMode::Idle);
        let allowed = Steps {
            step: limits.step + count(i),
            turn: limits.turn + 2.0 * count(i),
        };
        if !steps.within(allowed) {
            problems.push(format!(
                "{name}: the wake exceeds the idle limits ({:.0} m°/frame, {:.0} m°/frame²)",
                steps.step, steps.turn
            ));
        }
    }
}

/// The angle, m°, of `pulse` on the servo of axis `i` ([`Axis::index`]).
fn degrees(i: usize, pulse: &Pulse) -> f64 {
    angle(i, f64::from(pulse.counts) * run::timing().count_ns)
}

/// One count of the servo clock (312.5 ns) on the servo of axis `i`, m°
/// (28.1): the rounding of a measured pulse.
fn count(i: usize) -> f64 {
    let count_ns = run::timing().count_ns;
    angle(i, count_ns) - angle(i, 0.0)
}

/// The glance (check 4): yaw (`(rise, m°)` a pulse) at the sensor's −20°
/// within 2.5° (the idle's sway) after the wake (at `after`), for about its
/// 2 s hold.
fn glance(yaw: impl Iterator<Item = (f64, f64)>, after: f64, problems: &mut Vec<String>) {
    let near = yaw
        .filter(|&(rise, angle)| rise > after && (angle - SENSOR_YAW).abs() < 2_500.0)
        .count();
    println!("yaw: {near} pulses within 2.5° of the sensor's −20°");
    if near < 90 {
        problems.push(format!(
            "the head did not glance towards the sensor: {near} frames near −20°"
        ));
    }
}
