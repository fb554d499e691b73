//! The emulator stages without a module of their own: pulses at 50 and
//! 333 Hz, the watchdog drill, the console, the emulator's failures.

use std::{
    path::{Path, PathBuf},
    time::Duration,
};

use anyhow::{Context, Result};
use idle_head_core::servo::ServoRate;
use xshell::cmd;

use super::{
    DEFAULT_TIME,
    event::End,
    exchange,
    image::{PicoImage, SERVOS, VECTOR_TABLE},
    node,
    run::{self, Report},
    script,
};
use crate::{
    elf,
    project::{self, Metadata, PICO, TARGET},
    reference,
};

pub const PULSES_STAGE: &str =
    "Pico image in the RP2040 emulator: every pulse the host's duty, frame for frame";
pub const DRILL_STAGE: &str =
    "watchdog drill in the RP2040 emulator: reset, logged, soft start again";
pub const CONSOLE_STAGE: &str = "Pico image in the RP2040 emulator: the console's UART and USB \
     exchanges; its RAM within budget";
pub const RATE_STAGE: &str = "Pico image in the RP2040 emulator at 333 Hz (booted on saved \
     settings): every pulse the host trace's duty, frame for frame";
pub const FAILURES_STAGE: &str =
    "RP2040 emulator: a hung, a sleeping and a wrong image each fail clearly";

/// Frames the pulse check must cover: a whole loop (1500) and then some.
const MIN_FRAMES: usize = 1600;
pub use super::run::WALL;
/// As in `crates/firmware/src/hooks.rs`: the drill's frames in each boot,
/// the watchdog timeout.
const DRILL_FRAMES: usize = 150;
const WATCHDOG_MS: f64 = 100.0;
/// The console run: UART script at 3 s, USB at 4 s, a second for replies.
pub const CONSOLE_TIME: Duration = Duration::from_secs(6);

/// The script of [`RATE_STAGE`]: the fade-in, then a nod, a look and its
/// return over a shake, an idle change and a move back, all at 333 Hz.
const RATE_SCRIPT: &str = "\
2.2 nod
2.6 look 8000 -15000 hold=700
3.0 shake intensity=80
4.1 idle amp 50
4.6 tilt -9000 1200
5.4 center
";

/// [`RATE_STAGE`]: [`RATE_SCRIPT`] for 7 s into the image booted on 333 Hz
/// settings, every pulse against the host trace at 333 Hz.
pub fn test_rate(root: &Path, metadata: &Metadata) -> Result<()> {
    let board = script::Board {
        rate: ServoRate::MAX,
        uid: None,
    };
    let report = script::host(root, metadata, RATE_SCRIPT, Duration::from_secs(7), board)?;
    print!("{}", report.table());
    let frames = report.boots.first().map_or(0, |boot| boot.servos[0].frames);
    let few = format!("{frames} frames checked, not the 2,300 of 7 s at 333 Hz");
    report.conclude((frames < 2300).then_some(few))
}

/// The shipped image for [`DEFAULT_TIME`]: every check passes over at least
/// [`MIN_FRAMES`] frames, the loops' checksum the host's. Returns the run.
pub fn test_pulses(root: &Path, metadata: &Metadata) -> Result<Report> {
    let report = checked_run(root, metadata, DEFAULT_TIME, WALL, |_| {})?;
    print!("{}{}", report.log_text(false), report.table());
    let (mut problems, frames) = (Vec::new(), report.frames());
    if frames < MIN_FRAMES {
        problems.push(format!("{frames} frames checked, fewer than {MIN_FRAMES}"));
    }
    if report.watchdog_resets() > 0 {
        problems.push("the watchdog reset the shipped image".to_owned());
    }
    let want = format!("checksum {:#010x}", reference::checksum()?);
    if !report.boots.iter().any(|b| b.says(&want)) {
        problems.push(format!(
            "no `precompute: ...; {want}` line, the host's checksum"
        ));
    }
    report.conclude(problems)?;
    Ok(report)
}

/// The shipped image (built) run for `time` (at most `wall`) with the
/// harness set up by `setup`, every pulse checked against the host's idle.
pub fn checked_run(
    root: &Path,
    metadata: &Metadata,
    time: Duration,
    wall: Duration,
    setup: impl FnOnce(&mut node::Config),
) -> Result<Report> {
    let mut report = super::run_shipped(root, metadata, time, wall, setup)?;
    run::check(&mut report)?;
    Ok(report)
}

/// Runs two boots of the drill image (each 3 s of frames and the timeout);
/// checks the reset and the soft start after it.
pub fn test_drill(root: &Path, metadata: &Metadata) -> Result<()> {
    let elf = build_drill(metadata)?;
    let mut report = run::run_with(root, &elf, Duration::from_millis(6_500), WALL, |_| {})?;
    run::check(&mut report)?;
    print!("{}{}", report.log_text(false), report.table());
    let mut problems = Vec::new();
    let stop = format!("frames stop after frame {DRILL_FRAMES}");
    let neutral = "first frame: neutral pulses 1500 1500 1500 us";
    for (boot, text, what) in [
        (0, "boot: power-on", "a power-on boot"),
        (0, &stop, "the drill's stop"),
        (1, "last reset by the WATCHDOG", "the watchdog reset"),
        (1, neutral, "neutral first pulses"),
    ] {
        let logged = report.boots.get(boot).is_some_and(|b| b.says(text));
        problem_if!(problems, !logged, "boot {boot} did not log {what}");
    }
    if !report.first()?.watchdog {
        problems.push("the watchdog did not reset the board after the frames stopped".to_owned());
    }
    for (b, boot) in report.boots.iter().enumerate().filter(|b| b.1.watchdog) {
        for (check, (name, ..)) in boot.servos.iter().zip(SERVOS) {
            // Frames 0..=DRILL_FRAMES, each its own pulse: neutral first and
            // the 2 s fade-in (checked against the host) before the stop.
            let (fresh, held, want) = (check.fresh, check.held, DRILL_FRAMES + 1);
            let servo = format!("boot {b}, {name}");
            if fresh != want {
                problems.push(format!("{servo}: {fresh} frames went out, not {want}"));
            }
            // The last duty is held until the reset, 100 ms: 5 periods.
            if held > 6 {
                problems.push(format!("{servo}: {held} pulses held before the reset"));
            }
        }
        let last_write = boot.trains[0].writes.last().map_or(boot.start, |w| w.0);
        let after = (boot.end - last_write) / 1e6;
        println!("boot {b}: watchdog reset {after:.3} ms after the last frame");
        if !(WATCHDOG_MS - 20.0..=WATCHDOG_MS + 1.0).contains(&after) {
            problems.push(format!(
                "boot {b}: the watchdog reset came {after:.3} ms after the last frame, not {WATCHDOG_MS} ms"
            ));
        }
    }
    report.conclude(problems)
}

/// Builds the drill image (`--features watchdog-drill`) into
/// `target/watchdog-drill/`, beside the shipped one; its ELF.
pub fn build_drill(metadata: &Metadata) -> Result<PathBuf> {
    let build_dir = metadata.target_dir.to_string_lossy();
    let target = metadata.target_dir.join("watchdog-drill");
    if !project::prebuilt() {
        let sh = project::shell(".")?;
        let build = cmd!(
            sh,
            "cargo build --release --features watchdog-drill --target-dir {target}"
        );
        let env = [
            project::FIRMWARE_ENV[0],
            ("CARGO_BUILD_BUILD_DIR", &build_dir),
        ];
        project::run(&sh, &env, build)?;
    }
    Ok(target.join(TARGET).join("release").join(PICO.bin))
}

/// The UART and USB exchanges: fails on a wrong reply, pulse or run, or
/// the RAM (static plus measured peak stack) over budget.
pub fn test_console(
    root: &Path,
    metadata: &Metadata,
    virtual_time: Duration,
    wall: Duration,
) -> Result<()> {
    let mut report = checked_run(root, metadata, virtual_time, wall, exchange::configure)?;
    print!("{}", report.log_text(false));
    exchange::check(&mut report);
    print!("{}", report.table());
    report.conclude(console_ram(metadata, &report)?)
}

/// Prints the shipped image's RAM (static plus `report`'s peak stack); a
/// problem if over.
pub fn console_ram(metadata: &Metadata, report: &Report) -> Result<Option<String>> {
    let static_ram = elf::Image::read(&PICO.elf(metadata))?.static_ram();
    let Some(stack) = report.peak_stack() else {
        let problem = format!("Pico image RAM: {static_ram} B static, but no peak stack measured");
        return Ok(Some(problem));
    };
    let (ram, budget) = (static_ram + stack, elf::RAM_BUDGET);
    let sum = format!("{ram} B (static {static_ram} B + peak stack {stack} B)");
    println!("Pico image RAM: {sum} of the {budget} B budget");
    Ok((ram > budget).then(|| format!("Pico image RAM {sum} is over the {budget} B budget")))
}

/// A hung, a sleeping, a slow image and non-images: each fails clearly.
pub fn test_failures(root: &Path, metadata: &Metadata) -> Result<()> {
    node::ensure(root)?;
    let dir = metadata.target_dir.join("sim-failures");
    std::fs::create_dir_all(&dir)?;
    // Thumb `b .` (a loop on itself) and `wfi`; the runs' virtual time,
    // wall time and silence.
    let (b_self, wfi) = (0xe7fe, 0xbf30);
    let [short, slow] = [50, 200].map(Duration::from_millis);
    let [two, long] = [2, 3600].map(Duration::from_secs);
    let hung = "no log byte and no pin edge";
    let asleep = "sleeps with nothing left to wake it";
    let cases: [(&str, &[u16], [Duration; 3], &str); 3] = [
        ("hung", &[b_self], [two, WALL, short], hung),
        ("asleep", &[wfi, b_self], [two, WALL, short], asleep),
        ("slow", &[b_self], [long, slow, long], "stopped after"),
    ];
    let mut problems = Vec::new();
    for (name, code, [virtual_time, wall, silence], want) in cases {
        let flash = dir.join(format!("{name}.bin"));
        std::fs::write(&flash, synthetic(code)).context("writing a test image")?;
        let config = node::Config {
            flash,
            vtor: VECTOR_TABLE,
            virtual_time,
            wall,
            silence,
            ..node::Config::default()
        };
        match End::of(&node::run(root, &config)?)?.problem(silence) {
            Some(message) if message.contains(want) => println!("{name}: {message}"),
            other => problems.push(format!("{name}: expected `{want}`, got {other:?}")),
        }
    }
    for (path, want) in [
        (dir.join("no-such-elf"), "cargo build --release"),
        (crate::project::exe()?, "is not a Pico image"),
    ] {
        let (read, path) = (PicoImage::read(&path), path.display());
        match read {
            Err(error) if format!("{error:#}").contains(want) => println!("{path}: {error:#}"),
            other => problems.push(format!("{path}: expected `{want}`, got {other:?}")),
        }
    }
    project::verdict(&problems)
}

/// A flash image: 256 bytes where boot2 would be, a vector table (stack at
/// the top of RAM, reset handler right behind it) and `code`.
fn synthetic(code: &[u16]) -> Vec<u8> {
    let mut flash = vec![0xff; 0x100];
    #[allow(clippy::cast_possible_truncation)] // addresses of the RP2040, 32 bits
    let reset = (VECTOR_TABLE + 8) as u32 | 1;
    flash.extend(0x2004_0000_u32.to_le_bytes());
    flash.extend(reset.to_le_bytes());
    flash.extend(code.iter().flat_map(|half| half.to_le_bytes()));
    flash
}
