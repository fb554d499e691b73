//! Show control: `cargo xtask sim --dmx FILE`, and the stage: DMX and
//! Bottango drive the head, lost frames and a curve's end hand it back to
//! the idle (docs/dev/emulators.md, "Show control").

use std::{path::Path, time::Duration};

use anyhow::Result;
use idle_head_core::bottango::hash;
use idle_head_core::driver::DriverConfig;

use super::{
    DEFAULT_TIME, dmx, expect,
    image::SERVOS,
    node::Chunk,
    pulses::{self, Measured, angle},
    pulses_csv,
    run::{self, Boot},
    stages,
};
use crate::project::{self, Metadata};
use crate::steps::Steps;

pub const SHOW_STAGE: &str = "Pico image in the RP2040 emulator: DMX and Bottango drive the \
     head, lost frames and the end of a curve hand back to the idle";

/// The stage's DMX script.
const SCRIPT: &str = "\
3.0 7=0 8=0 9=255 1=0 3=128 5=128
3.5 7=255 1=200
5.0 dmx stop
7.0 7=0 1=0
7.5 8=20
9.0 dmx stop
";

/// When the Bottango session starts, and `STOP`.
const BOTTANGO: Duration = Duration::from_millis(10_500);
const STOP: Duration = Duration::from_millis(12_600);

/// The session: handshake, sync, yaw and pitch registered, a 1 s eased
/// curve each 200 ms after the sync.
const SESSION: [&str; 6] = [
    "hRQ,144",
    "tSYN,0",
    "rMTR,yaw,-20000,20000,3000,4096",
    "rMTR,pitch,-10000,10000,3000,4096",
    "sC,yaw,200,1000,4096,333,0,8192,-333,0",
    "sC,pitch,200,1000,4096,333,0,6144,-333,0",
];

/// Bottango lines with their hashes.
pub fn bottango_lines(bodies: &[&str]) -> Vec<String> {
    let line = |body: &&str| format!("{body},h{}\n", hash(body.as_bytes()));
    bodies.iter().map(line).collect()
}

/// `cargo xtask sim --dmx FILE [--pulses FILE.csv]` (either alone too):
/// the run's log and pulses, not checked against the host.
pub fn command(root: &Path, metadata: &Metadata, args: &super::Args) -> Result<bool> {
    let changes = args.dmx.as_deref().map(dmx::read).transpose()?;
    let last = changes.as_ref().and_then(|c| c.last());
    let last = last.map(|last| last.at + Duration::from_secs(3));
    let time = args.virtual_time.or(last).unwrap_or(DEFAULT_TIME);
    let report = super::run_shipped(root, metadata, time, args.timeout, |config| {
        config.dmx = changes.as_deref().map(dmx::line);
    })?;
    print!("{}", report.log_text(args.verbose));
    let boot = report.first()?;
    print_pulses(boot, args.pulses.as_deref())?;
    if let Some(changes) = &changes {
        let (n, carried) = (changes.len(), boot.dmx_changes.len());
        let from = changes.first().map_or(0.0, |c| c.at.as_secs_f64());
        println!("dmx: {n} change(s) from {from:.3} s on, {carried} frame(s) carrying one");
    }
    for problem in &report.problems {
        println!("problem: {problem}");
    }
    Ok(report.problems.is_empty())
}

/// Per servo: pulses, shortest, longest; with `csv`, their CSV.
fn print_pulses(boot: &Boot, csv: Option<&Path>) -> Result<()> {
    println!("\nservo   pulses   min µs   max µs");
    for ((name, ..), train) in SERVOS.iter().zip(&boot.trains) {
        let widths: Vec<f64> = pulses::measure(train)
            .iter()
            .map(|p| p.width / 1e3)
            .collect();
        let min = widths.iter().copied().fold(f64::INFINITY, f64::min);
        let max = widths.iter().copied().fold(0.0, f64::max);
        println!("{name:<6} {:>7} {min:>8.1} {max:>8.1}", widths.len());
    }
    csv.map_or(Ok(()), |path| {
        pulses_csv::write(path, &boot.trains, &run::timing())
    })
}

/// The stage: see the [module docs](self).
pub fn test_show(root: &Path, metadata: &Metadata) -> Result<()> {
    show(root, metadata, None)
}

/// `cargo xtask sim --show [--pulses FILE.csv]`: the stage.
pub fn show(root: &Path, metadata: &Metadata, pulses: Option<&Path>) -> Result<()> {
    let changes = dmx::parse(SCRIPT)?;
    let lines = bottango_lines(&SESSION);
    let time = Duration::from_secs(14);
    let report = super::run_shipped(root, metadata, time, stages::WALL, |config| {
        config.dmx = Some(dmx::line(&changes));
        let stop = Chunk::new(b"STOP,h326\n", STOP);
        config.usb = vec![Chunk::new(lines.concat(), BOTTANGO), stop];
    })?;
    print!("{}", report.log_text(false));
    let boot = report.first()?;
    print_pulses(boot, pulses)?;
    let mut problems = check(boot, &lines)?;
    problems.extend(report.problems.iter().cloned());
    problems.extend(stages::console_ram(metadata, &report)?);
    let boots = report.boots.len();
    if boots != 1 {
        problems.push(format!("{boots} boots: the watchdog reset the image"));
    }
    project::verdict(&problems)
}

/// The pulses of one run, per servo, with the host's idle duties.
struct Pulses {
    servos: [Vec<Measured>; 3],
    idle: Vec<[u16; 3]>,
}

impl Pulses {
    /// `axis`' pulses rising within `[from, to)` s: their index, time (s)
    /// and angle (°).
    fn window(&self, axis: usize, from: f64, to: f64) -> Vec<(usize, f64, f64)> {
        (self.servos[axis].iter().enumerate())
            .filter(|(_, p)| (from * 1e9..to * 1e9).contains(&p.rise))
            .map(|(n, p)| (n, p.rise / 1e9, angle(axis, p.width) / 1e3))
            .collect()
    }

    /// The pulses of every axis rising within `[from, to)` s that are not
    /// the idle's own (the host's duty, within a count).
    fn off_idle(&self, from: f64, to: f64) -> Vec<String> {
        let mut off = Vec::new();
        for axis in 0..3 {
            for (n, t, _) in self.window(axis, from, to) {
                let counts = self.servos[axis][n].width / run::timing().count_ns;
                let want = self.idle.get(n).map_or(0.0, |d| f64::from(d[axis]));
                let name = SERVOS[axis].0;
                if (counts - want).abs() > 1.5 {
                    off.push(format!(
                        "{name} at {t:.3} s: {counts:.0} counts, not {want}"
                    ));
                }
            }
        }
        off
    }

    /// The largest change of `axis`' angle from one pulse to the next within
    /// `[from, to)` s, °.
    fn fastest(&self, axis: usize, from: f64, to: f64) -> f64 {
        let angles: Vec<f64> = self.window(axis, from, to).iter().map(|w| w.2).collect();
        Steps::of(&angles).step
    }

    /// The highest angle of `axis` within `[from, to)` s, °.
    fn top(&self, axis: usize, from: f64, to: f64) -> f64 {
        self.window(axis, from, to)
            .iter()
            .map(|w| w.2)
            .fold(f64::MIN, f64::max)
    }
}

/// The acceptance checks on boot 0: prints what they found; the problems.
#[allow(clippy::too_many_lines)] // one check after another, in the order of the module docs
fn check(boot: &Boot, lines: &[String]) -> Result<Vec<String>> {
    let servos = boot.trains.each_ref().map(pulses::measure);
    let frames = servos.iter().map(Vec::len).max().unwrap_or(0);
    let idle = expect::pico_duties(frames)?;
    let p = Pulses { servos, idle };
    let mut problems = Vec::new();
    let (yaw, pitch) = (2, 0);
    // The gesture limit, 250 °/s, in ° a frame, and a count of rounding.
    let step = 250.0 * 0.02 + 0.5 * 0.0111;

    // 1. Mix 255, yaw coarse 200.
    let limits = DriverConfig::DEFAULT.servos[yaw].limits;
    let [lo, hi] = [limits.min, limits.max].map(|a| f64::from(a.millidegrees()) / 1e3);
    let want = lo + (hi - lo) * 51_200.0 / 65_535.0;
    let held = p.window(yaw, 4.3, 5.0);
    let worst = held.iter().map(|w| (w.2 - want).abs()).fold(0.0, f64::max);
    let fastest = p.fastest(yaw, 3.4, 5.0);
    let at = held.last().map_or(f64::NAN, |w| w.2);
    println!(
        "dmx mix 255, yaw coarse 200: yaw at {at:.3}° ({:.4} of its way, 200/255 = {:.4}), at \
         most {worst:.3}° off over {} pulses; fastest step {fastest:.2}° a frame (limit {step:.2}°)",
        (at - lo) / (hi - lo),
        200.0 / 255.0,
        held.len(),
    );
    problem_if!(
        problems,
        held.len() < 30 || worst > 0.1,
        "yaw did not hold {want:.3}° under DMX (off by {worst:.3}°)"
    );
    problem_if!(
        problems,
        fastest > step,
        "a yaw step of {fastest:.3}° a frame: past the speed limit"
    );

    // 2. The frames dropped at 5 s: lost at 6 s, and the idle's own pulses.
    let lost: Vec<f64> = (boot.log.iter())
        .filter(|(_, l)| l.message.contains("dmx: signal lost"))
        .map(|(ns, _)| ns / 1e9)
        .collect();
    println!("dmx signal lost at {lost:.3?} s (frames dropped at 5.0 s and 9.0 s)");
    problem_if!(
        problems,
        !lost.first().is_some_and(|&t| (5.95..6.2).contains(&t)),
        "the first `dmx: signal lost` came at {lost:?} s, not 1 s after 5.0 s"
    );
    let jumps: Vec<String> = (0..3)
        .map(|axis| (SERVOS[axis].0, p.fastest(axis, 5.0, 7.0)))
        .filter(|&(_, fastest)| fastest > step)
        .map(|(name, fastest)| format!("{name} {fastest:.3}°"))
        .collect();
    let after_loss = p.off_idle(6.8, 7.0);
    println!(
        "hand-back: jumps past the limit: {jumps:?}; pulses off the idle's from 6.8 s to 7.0 s: {}",
        after_loss.len()
    );
    let jumped = jumps.join(", ");
    problem_if!(
        problems,
        !jumps.is_empty(),
        "a jump after the frames dropped: {jumped}"
    );
    if let Some(first) = after_loss.first() {
        problems.push(format!(
            "not the idle's own pulses after the hand-back: {first}"
        ));
    }

    // 3. One nod from the band entry at 7.5 s.
    let nods = (boot.log.iter())
        .filter(|(_, l)| l.message.contains(": dmx nod: ok"))
        .count();
    let during = p.off_idle(7.5, 8.5).len();
    let after = p.off_idle(9.3, 10.5);
    println!(
        "dmx trigger 20 (nod band) at 7.5 s: {nods} nod(s) logged, {during} pulses off the idle's \
         during it, {} after it (9.3 s to 10.5 s)",
        after.len()
    );
    problem_if!(
        problems,
        nods != 1,
        "{nods} nods logged for one band entry, not 1"
    );
    problem_if!(
        problems,
        during < 20,
        "only {during} pulses of a nod: the band entry played none"
    );
    problems.extend(after.first().map(|p| format!("the nod went on: {p}")));

    // 4. Bottango over USB: yaw past 10° 0.7 s after the lines (0.2 s and
    // half the curve, a frame either way), at the curve's 20° at its top.
    let usb = String::from_utf8_lossy(&boot.usb).into_owned();
    let oks = usb.matches("OK\n").count();
    let handshake = usb.contains("btngoHSK,0.8.0c1,144\nOK\n");
    let sent = boot.usb_in.first().map_or(f64::NAN, |ns| ns / 1e9);
    let curve = p.window(yaw, sent, sent + 2.0);
    let top = p.top(yaw, sent, sent + 2.0);
    let crossing = curve
        .iter()
        .find(|w| w.2 >= 10.0)
        .map_or(f64::NAN, |w| w.1 - sent);
    let back = p.off_idle(sent + 1.9, STOP.as_secs_f64() + 1.3);
    println!(
        "Bottango (USB from {sent:.3} s): handshake {handshake}, {oks} OK for {} lines; yaw past \
         10° {crossing:.3} s after the lines, top {top:.3}°; pulses off the idle's after the \
         hand-back: {}",
        lines.len() + 1,
        back.len()
    );
    problem_if!(
        problems,
        !handshake || oks != lines.len() + 1,
        "Bottango's session was not answered as expected: {usb:?}"
    );
    problem_if!(
        problems,
        !(0.64..0.78).contains(&crossing),
        "yaw crossed 10° {crossing:.3} s after the curve was sent, not about 0.7 s"
    );
    for (axis, want) in [(yaw, 20.0), (pitch, 5.0)] {
        let (name, top) = (SERVOS[axis].0, p.top(axis, sent, sent + 2.0));
        problem_if!(
            problems,
            (top - want).abs() > 0.15,
            "{name} topped at {top:.3}°, not the curve's {want}°"
        );
    }
    if let Some(first) = back.first() {
        problems.push(format!("the idle did not resume after the curve: {first}"));
    }
    Ok(problems)
}
