//! Runs the QEMU image and decodes its defmt log; `cargo xtask qemu`.

use std::{
    io::{BufRead, BufReader, Read, Write},
    path::Path,
    process::{Command, Stdio},
    time::{Duration, Instant},
};

use anyhow::{Context, Result, bail};

use crate::figures::{self, thousands};
use crate::{
    args::Options,
    log::{Defmt, LogLine, Run},
    plot,
    project::{self, QEMU},
    reference,
    setup::{self, QEMU_BINARY},
    snapshot,
};

/// What QEMU 7.2 prints at every start of the `lm3s6965evb` machine, before
/// the firmware runs: the board's watchdog model starts its timer at reset,
/// while the system clock that drives it still reads 0 Hz (it is set a moment
/// later). The watchdog then stays stopped until a program loads it, which
/// these images never do, so the line says nothing about the run and is not
/// shown. Later QEMU releases no longer start the watchdog at reset.
const RESET_NOISE: &str = "Timer with period zero, disabling";

/// `cargo xtask qemu`: build, run, show. `Ok(false)` when the run failed.
pub fn command(options: Options) -> Result<bool> {
    let root = project::root();
    setup::ensure_toolchain(&root)?;
    setup::ensure_qemu()?;
    let metadata = project::metadata(&root)?;
    QEMU.build(&root)?;
    let run = run(&QEMU.elf(&metadata), options.timeout, Echo::All)?;

    println!();
    let png = metadata.target_dir.join("qemu").join("motion.png");
    match plot_motion(&run.log, &png) {
        Ok(frames) => println!("motion: {frames} logged frames drawn in {}", png.display()),
        Err(error) => println!("motion: not drawn: {error:#}"),
    }
    println!("{}", run.describe());
    let mut ok = run.succeeded();
    match check_summary(&run.log) {
        Ok(line) => {
            println!("{line}");
            record_figures(&run.log);
        }
        Err(error) => {
            println!("summary check failed: {error:#}");
            ok = false;
        }
    }
    if options.bless {
        if run.succeeded() {
            snapshot::bless(&run)?;
        } else {
            println!("not re-recording the expected log: the run failed");
        }
    }
    Ok(ok)
}

/// How much of the log to print while QEMU runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Echo {
    /// Every decoded line.
    All,
    /// Warnings and errors only (with their source location).
    Problems,
    /// Nothing (the caller shows what it wants once QEMU is done).
    Quiet,
}

/// QEMU running `elf` with the options `args` (display, semihosting,
/// serial ports). `-icount shift=0` makes one instruction one nanosecond of
/// virtual time; `sleep=off` lets the virtual clock jump over the time the
/// core sleeps (timing, and so the log, repeat exactly run after run),
/// `sleep=on` follows the wall clock while it sleeps (a head at its true
/// speed, for a person).
pub fn qemu_command(elf: &Path, sleep: bool, args: &[&str]) -> Command {
    let mut command = Command::new(QEMU_BINARY);
    let icount = if sleep {
        "shift=0,sleep=on"
    } else {
        "shift=0,sleep=off"
    };
    command.args([
        "-machine",
        "lm3s6965evb",
        "-cpu",
        "cortex-m0",
        "-icount",
        icount,
    ]);
    command.args(args).arg("-kernel").arg(elf);
    command
}

/// Runs `elf` in QEMU, decoding its defmt output as it arrives; QEMU is
/// killed after `timeout` of wall time.
pub fn run(elf: &Path, timeout: Duration, echo: Echo) -> Result<Run> {
    let defmt = Defmt::read(elf)?;

    let mut command = qemu_command(
        elf,
        false,
        &[
            "-nographic",
            "-semihosting-config",
            "enable=on,target=native",
        ],
    );
    println!("$ {}", project::shown(&command));
    command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let start = Instant::now();
    let child = command
        .spawn()
        .with_context(|| format!("could not start {QEMU_BINARY}"))?;
    // The log is decoded while QEMU runs; its end is the end of QEMU's
    // output, which comes when QEMU exits or is killed.
    let done = project::finish(
        child,
        QEMU_BINARY,
        timeout,
        |stdout| decode(stdout, &defmt, echo),
        |stderr| forward(stderr, &mut std::io::stderr()),
        || (),
    )?;
    Ok(Run {
        log: done.stdout,
        exit: done.exit,
        elapsed: start.elapsed(),
    })
}

/// Decodes the defmt stream `output` to its end, echoing lines as they come.
pub(crate) fn decode(mut output: impl Read, defmt: &Defmt, echo: Echo) -> Vec<LogLine> {
    let mut decoder = defmt.stream();
    let mut buffer = [0_u8; 4096];
    let mut log = Vec::new();
    while let Ok(n @ 1..) = output.read(&mut buffer) {
        for line in defmt.lines(decoder.as_mut(), &buffer[..n]) {
            if echo == Echo::All || (echo == Echo::Problems && line.is_problem()) {
                line.print();
            }
            log.push(line);
        }
    }
    log
}

/// Whether `line` is QEMU's [`RESET_NOISE`].
pub(crate) fn is_reset_noise(line: &str) -> bool {
    line == RESET_NOISE
}

/// Passes QEMU's messages on, all but [`RESET_NOISE`].
fn forward(stderr: impl Read, to: &mut impl Write) {
    for line in BufReader::new(stderr).lines().map_while(Result::ok) {
        if line != RESET_NOISE {
            let _ = writeln!(to, "{line}");
        }
    }
}

/// The firmware's closing `summary key=value ...` line, as fields.
#[derive(Debug)]
pub struct Summary {
    fields: Vec<(String, String)>,
}

impl Summary {
    /// Finds the last line of `log` whose message starts with `summary`.
    pub fn find(log: &[LogLine]) -> Option<Self> {
        let line = log
            .iter()
            .rev()
            .find(|line| line.message.trim_start().starts_with("summary"))?;
        let fields = line
            .message
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter_map(|token| token.split_once('='))
            .map(|(key, value)| (key.to_owned(), value.to_owned()))
            .collect();
        Some(Self { fields })
    }

    /// The value of `key`, if present.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, value)| value.as_str())
    }

    /// The value of `key` as a number (decimal, or hexadecimal with `0x`).
    pub fn number(&self, key: &str) -> Result<u64> {
        let value = self
            .get(key)
            .with_context(|| format!("the summary line has no `{key}=`"))?;
        let parsed = match value
            .strip_prefix("0x")
            .or_else(|| value.strip_prefix("0X"))
        {
            Some(hex) => u64::from_str_radix(&hex.replace('_', ""), 16),
            None => value.replace('_', "").parse(),
        };
        parsed.with_context(|| format!("`{key}={value}` in the summary line is not a number"))
    }
}

/// Checks the summary line: no missed frames, no pulse violations, and the
/// checksum of the loops the firmware generated equals the one generated on
/// the host by the same core library. Returns a one-line verdict.
pub fn check_summary(log: &[LogLine]) -> Result<String> {
    let summary = Summary::find(log).context("the log has no `summary ...` line")?;
    let missed = summary.number("missed")?;
    let violations = summary.number("pulse_violations")?;
    let firmware = summary.number("checksum")?;
    let host = reference::checksum()?;
    let mut problems = Vec::new();
    if missed != 0 {
        problems.push(format!("missed={missed} (want 0)"));
    }
    if violations != 0 {
        problems.push(format!("pulse_violations={violations} (want 0)"));
    }
    if firmware != u64::from(host) {
        problems.push(format!(
            "checksum={firmware:#010x} but the host computes {host:#010x}"
        ));
    }
    if problems.is_empty() {
        Ok(format!(
            "summary ok: missed=0 pulse_violations=0 checksum={host:#010x} (matches the host)"
        ))
    } else {
        bail!("{}", problems.join(", "))
    }
}

/// Draws the three axes of the log's frame lines (`frame <n>: pitch=<deg>
/// roll=<deg> yaw=<deg> deg, ...`: the decoder hands out text, so the log
/// is the record) to the PNG `path`; returns how many there were.
fn plot_motion(log: &[LogLine], path: &Path) -> Result<usize> {
    let mut frames: Vec<(f64, [f64; 3])> =
        log.iter().filter_map(|l| frame_line(&l.message)).collect();
    frames.sort_by(|a, b| a.0.total_cmp(&b.0));
    if frames.len() < 2 {
        bail!("fewer than two frame lines in the log");
    }
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

/// The QEMU smoke run's boot precompute (`precompute_insns` of its summary
/// line) and the loop sets its log reports. Only the smoke run's: a run
/// with console traffic would count that traffic in its sets' times.
#[allow(clippy::cast_precision_loss)] // instruction counts, far below 2^52
pub fn record_figures(log: &[LogLine]) {
    let at_125_mhz = |insns: u64| format!("≥ {:.2} ms", insns as f64 / 125e3);
    let boot = Summary::find(log).and_then(|s| s.number("precompute_insns").ok());
    let boot = boot.map(|i| {
        vec![
            "0 (boot)".to_owned(),
            thousands(i),
            at_125_mhz(i),
            "none".to_owned(),
        ]
    });
    let sets =
        log.iter()
            .filter_map(|line| set_cost(&line.message))
            .map(|(set, insns, discarded)| {
                vec![
                    set.to_string(),
                    thousands(insns),
                    at_125_mhz(insns),
                    discarded,
                ]
            });
    let intro = "The QEMU smoke run's loop sets ([never-repeating idle](idle.md#in-the-background)): \
                 the boot's set 0, timed before the first frame, and the sets generated in the \
                 background while the frames play, each with the loops it discarded per axis \
                 (pitch, roll, yaw).";
    let header = ["set", "instructions", "at 125 MHz", "loops discarded"];
    figures::record(
        "qemu",
        intro.to_owned(),
        &header,
        boot.into_iter().chain(sets).collect(),
    );
}

/// `loop set <n> ready in <µs> us: seeds [..] ([..] discarded), ...`: the
/// set, its instructions and the loops it discarded.
fn set_cost(message: &str) -> Option<(u64, u64, String)> {
    let rest = message.strip_prefix("loop set ")?;
    let (set, rest) = rest.split_once(" ready in ")?;
    let (micros, rest) = rest.split_once(" us")?;
    // Virtual time under `-icount shift=0`: one instruction a nanosecond,
    // the frames that preempt the generator included.
    let instructions = micros.parse::<u64>().ok()?.checked_mul(1000)?;
    let discarded = rest
        .split_once('(')
        .and_then(|(_, after)| after.split_once(" discarded)"))
        .map_or_else(String::new, |(list, _)| list.to_owned());
    Some((set.parse().ok()?, instructions, discarded))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_last_summary_line() {
        let log = [
            "frame 0 pitch=0 roll=0 yaw=0",
            "summary frames=10 missed=3",
            "summary frames=900 missed=0 pulse_violations=0, checksum=0x1a2B_3c4d",
        ]
        .map(|message| LogLine::new("INFO", message));
        let summary = Summary::find(&log).unwrap();
        assert_eq!(summary.number("frames").unwrap(), 900);
        assert_eq!(summary.number("missed").unwrap(), 0);
        assert_eq!(summary.number("checksum").unwrap(), 0x1a2b_3c4d);
        assert!(summary.number("absent").is_err());
        assert!(Summary::find(&log[..1]).is_none());
    }

    #[test]
    fn only_the_reset_noise_is_dropped() {
        let stderr = format!("{RESET_NOISE}\nqemu-system-arm: a real problem\n");
        let mut shown = Vec::new();
        forward(stderr.as_bytes(), &mut shown);
        assert_eq!(shown, b"qemu-system-arm: a real problem\n");
    }

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

    #[test]
    fn reads_the_loop_set_lines() {
        let set = set_cost(
            "loop set 2 ready in 3470 us: seeds [0x417b904f, 0xcbb40bbb, \
             0xd00c5039] ([2, 3, 3] discarded), entered at [407, 233, 791], join mismatch \
             [1142, 1108, 1391] mdeg rms",
        )
        .unwrap();
        assert_eq!(set, (2, 3_470_000, "[2, 3, 3]".to_owned()));
        assert!(set_cost("loop set failed: range; trying the next seeds").is_none());
        assert!(set_cost("frame 1400: join").is_none());
    }
}
