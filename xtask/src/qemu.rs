//! Runs the QEMU image and decodes its defmt log; `cargo xtask qemu`.

use std::{
    io::{BufRead, BufReader, Read},
    path::Path,
    process::{Child, Command, Stdio},
    time::{Duration, Instant},
};

use anyhow::{Context, Result, ensure};

use crate::figures::{self, thousands};
use crate::{
    args::Options,
    log::{Defmt, LogLine, Run, number, summary},
    plot,
    project::{self, QEMU},
    reference,
    setup::{self, QEMU_BINARY},
    snapshot,
};

/// `cargo xtask qemu`: build, run, show. `Ok(false)` when the run failed.
pub fn command(options: Options) -> Result<bool> {
    let (root, metadata) = setup::prepare()?;
    setup::ensure_qemu()?;
    QEMU.build(&root)?;
    let run = run(&QEMU.elf(&metadata), options.timeout, Echo::All)?;
    let png = metadata.target_dir.join("qemu").join("motion.png");
    match plot_motion(&run.log, &png) {
        Ok(frames) => println!(
            "\nmotion: {frames} logged frames drawn in {}",
            png.display()
        ),
        Err(error) => println!("\nmotion: not drawn: {error:#}"),
    }
    println!("{}", run.describe());
    let checked = check_summary(&run.log);
    match &checked {
        Ok(line) => {
            println!("{line}");
            record_figures(&run.log);
        }
        Err(error) => println!("summary check failed: {error:#}"),
    }
    if options.bless && run.succeeded() {
        snapshot::bless(&run)?;
    } else if options.bless {
        println!("not re-recording the expected log: the run failed");
    }
    Ok(run.succeeded() && checked.is_ok())
}

/// How much of the log to print while QEMU runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Echo {
    All,
    /// Warnings and errors only (with their source location).
    Problems,
    /// Nothing (the caller shows what it wants once QEMU is done).
    Quiet,
}

/// QEMU running `elf` with `args`. `-icount shift=0`: an instruction a
/// nanosecond of virtual time; with `sleep` the clock follows the wall
/// clock while the core sleeps (a head at its true speed), without it
/// jumps over that time (the log repeats exactly run after run).
pub fn qemu_command(elf: &Path, sleep: bool, args: &[&str]) -> Command {
    let icount = format!("shift=0,sleep={}", if sleep { "on" } else { "off" });
    let mut command = Command::new(QEMU_BINARY);
    command.args(["-machine", "lm3s6965evb", "-cpu", "cortex-m0"]);
    command.args(["-icount", &icount]).args(args);
    command.arg("-kernel").arg(elf);
    command
}

/// Runs `elf` in QEMU, decoding its log as it comes; killed after `timeout`.
pub fn run(elf: &Path, timeout: Duration, echo: Echo) -> Result<Run> {
    let semihosting = [
        "-nographic",
        "-semihosting-config",
        "enable=on,target=native",
    ];
    let mut command = qemu_command(elf, false, &semihosting);
    let words = std::iter::once(command.get_program()).chain(command.get_args());
    let words: Vec<_> = words.map(|w| w.to_string_lossy()).collect();
    println!("$ {}", words.join(" "));
    let child = spawn(&mut command, Stdio::piped)?;
    Ok(finish(child, elf, timeout, echo, || ())?.0)
}

/// Starts QEMU's `command`, stdin closed, its stdout and stderr `output`.
pub fn spawn(command: &mut Command, output: fn() -> Stdio) -> Result<Child> {
    command
        .stdin(Stdio::null())
        .stdout(output())
        .stderr(output())
        .spawn()
        .with_context(|| format!("could not start {QEMU_BINARY}"))
}

/// Runs QEMU (`child`, running `elf`) to its end with [`project::finish`],
/// decoding its log (echoed as `echo` says), passing on its stderr's news.
pub fn finish<R>(
    child: Child,
    elf: &Path,
    timeout: Duration,
    echo: Echo,
    meanwhile: impl FnOnce() -> R,
) -> Result<(Run, R)> {
    let defmt = Defmt::read(elf)?;
    let start = Instant::now();
    let decode = |mut output: std::process::ChildStdout| {
        let (mut decoder, mut log) = (defmt.stream(), Vec::new());
        let mut buffer = [0_u8; 4096];
        while let Ok(n @ 1..) = output.read(&mut buffer) {
            for line in defmt.lines(decoder.as_mut(), &buffer[..n]) {
                if echo == Echo::All || (echo == Echo::Problems && line.is_problem()) {
                    line.print();
                }
                log.push(line);
            }
        }
        log
    };
    let forward = |stderr| {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let noise = [
                "Timer with period zero, disabling",
                "QEMU waiting for connection",
            ];
            if !noise.iter().any(|n| line.contains(n)) {
                eprintln!("{line}");
            }
        }
    };
    let done = project::finish(child, QEMU_BINARY, timeout, decode, forward, meanwhile)?;
    let (log, exit, elapsed) = (done.stdout, done.exit, start.elapsed());
    Ok((Run { log, exit, elapsed }, done.meanwhile))
}

/// Checks the summary line: no missed frame, no pulse violation, and the
/// loops' checksum the host's (same core library); a one-line verdict.
pub fn check_summary(log: &[LogLine]) -> Result<String> {
    let summary = summary(log).context("the log has no `summary ...` line")?;
    let mut problems = Vec::new();
    for key in ["missed", "pulse_violations"] {
        let count = number(summary, key)?;
        if count != 0 {
            problems.push(format!("{key}={count} (want 0)"));
        }
    }
    let (firmware, host) = (number(summary, "checksum")?, reference::checksum()?);
    if firmware != u64::from(host) {
        problems.push(format!(
            "checksum={firmware:#010x} but the host computes {host:#010x}"
        ));
    }
    project::verdict(&problems)?;
    Ok(format!(
        "summary ok: missed=0 pulse_violations=0 checksum={host:#010x} (matches the host)"
    ))
}

/// Draws the three axes of the log's frame lines to the PNG `path`; how
/// many there were.
fn plot_motion(log: &[LogLine], path: &Path) -> Result<usize> {
    let mut frames: Vec<(f64, [f64; 3])> =
        log.iter().filter_map(|l| frame_line(&l.message)).collect();
    frames.sort_by(|a, b| a.0.total_cmp(&b.0));
    ensure!(frames.len() >= 2, "fewer than two frame lines in the log");
    let title = format!("The QEMU run's motion: {} logged frames", frames.len());
    let notes = vec!["angles as the firmware logged them".to_owned()];
    plot::motion(path, title, notes, "frame", &frames, &[])?;
    Ok(frames.len())
}

/// The frame number and the three angles of a frame line, if `message` is one.
fn frame_line(message: &str) -> Option<(f64, [f64; 3])> {
    let (frame, rest) = message.strip_prefix("frame ")?.split_once(": ")?;
    let mut words = rest.split_whitespace();
    let mut angles = [0.0; 3];
    for (angle, axis) in angles.iter_mut().zip(["pitch", "roll", "yaw"]) {
        let value = words.next()?.strip_prefix(axis)?.strip_prefix('=')?;
        *angle = value.parse().ok()?;
    }
    Some((frame.parse().ok()?, angles))
}

/// The smoke run's boot precompute and loop sets (`loop set <n> ready in
/// <µs> us: … ([..] discarded) …`), for the measured figures. Only the
/// smoke run's: console traffic would count in its sets' times.
#[allow(clippy::cast_precision_loss)] // instruction counts, far below 2^52
pub fn record_figures(log: &[LogLine]) {
    let row = |set: String, insns: u64, discarded: String| {
        vec![
            set,
            thousands(insns),
            format!("≥ {:.2} ms", insns as f64 / 125e3),
            discarded,
        ]
    };
    let boot = summary(log).and_then(|s| number(s, "precompute_insns").ok());
    let boot = boot.map(|i| row("0 (boot)".to_owned(), i, "none".to_owned()));
    let sets = log.iter().filter_map(|line| {
        let rest = line.message.strip_prefix("loop set ")?;
        let (set, rest) = rest.split_once(" ready in ")?;
        let (micros, rest) = rest.split_once(" us")?;
        // An instruction a nanosecond, preempting frames included.
        let insns = micros.parse::<u64>().ok()?.checked_mul(1000)?;
        let discarded = rest
            .split_once('(')
            .and_then(|(_, a)| a.split_once(" discarded)"));
        let discarded = discarded.map_or("", |d| d.0).to_owned();
        Some(row(set.to_owned(), insns, discarded))
    });
    let intro = "The QEMU smoke run's loop sets ([never-repeating idle](idle.md#in-the-background)): \
                 the boot's set 0, timed before the first frame, and the sets generated in the \
                 background while the frames play, each with the loops it discarded per axis \
                 (pitch, roll, yaw).";
    let header = ["set", "instructions", "at 125 MHz", "loops discarded"];
    let rows = boot.into_iter().chain(sets).collect();
    figures::record("qemu", intro.to_owned(), &header, rows);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_frame_lines_only() {
        let line = "frame 1650: pitch=-2.440 roll=+2.285 yaw=+7.611 deg, pulses 1473 1525 1585 us \
                    (Written Written Failed(Other))";
        assert_eq!(frame_line(line), Some((1650.0, [-2.44, 2.285, 7.611])));
        for other in [
            "frame 1400: join: the next loop set blends in over 100 frames",
            "frame 7: pitch=+1.000 roll=+2.000 deg",
            "frame x: pitch=+1.000 roll=+2.000 yaw=+3.000 deg",
            "summary frames=1903 missed=0",
        ] {
            assert!(frame_line(other).is_none(), "{other}");
        }
    }
}
