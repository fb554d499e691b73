//! The emulator's stages of `cargo xtask test` that need no scenario file
//! of their own: the pulses at 50 and 333 Hz, the watchdog drill, the
//! console's exchanges and the emulator's own failures.

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
    script::{self, Against},
};
use crate::{
    elf,
    project::{self, Metadata, PICO, TARGET},
    reference,
};

/// Stage names.
pub const PULSES_STAGE: &str =
    "Pico image in the RP2040 emulator: every pulse the host's duty, frame for frame";
/// See [`PULSES_STAGE`].
pub const DRILL_STAGE: &str =
    "watchdog drill in the RP2040 emulator: reset, logged, soft start again";
/// See [`PULSES_STAGE`].
pub const CONSOLE_STAGE: &str = "Pico image in the RP2040 emulator: the console's UART and USB \
     exchanges; its RAM within budget";
/// See [`PULSES_STAGE`].
pub const RATE_STAGE: &str = "Pico image in the RP2040 emulator at 333 Hz (booted on saved \
     settings): every pulse the host trace's duty, frame for frame";
/// See [`PULSES_STAGE`].
pub const FAILURES_STAGE: &str =
    "RP2040 emulator: a hung, a sleeping and a wrong image each fail clearly";

/// Frames the pulse check must cover: a whole loop (1500) and then some.
const MIN_FRAMES: usize = 1600;
/// Wall-time limit of one emulator run.
pub const WALL: Duration = Duration::from_secs(120);
/// The drill image stops its frames after this many frames of each boot
/// (`DRILL_FRAMES` in `crates/firmware/src/hooks.rs`).
const DRILL_FRAMES: usize = 150;
/// The Pico's watchdog timeout (`WATCHDOG_TIMEOUT` in `crates/firmware/src/hooks.rs`).
const WATCHDOG_MS: f64 = 100.0;
/// The console run: both scripts (UART at 3 s, USB at 4 s) and a second
/// for the last replies.
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

/// [`RATE_STAGE`]: the shipped image booted on settings of 333 Hz and
/// [`RATE_SCRIPT`] played into it for 7 s; every pulse checked against the
/// host trace at 333 Hz (its 3003 µs period, 60 060 counts of 50 ns).
pub fn test_rate(root: &Path, metadata: &Metadata) -> Result<()> {
    let events = script::parse(RATE_SCRIPT)?;
    let time = (Duration::from_secs(7), WALL);
    let report = script::play(
        root,
        metadata,
        events,
        time,
        Against::Host,
        script::Board {
            rate: ServoRate::MAX,
            uid: None,
        },
    )?;
    print!("{}", report.table());
    let frames = report.boots.first().map_or(0, |boot| boot.servos[0].frames);
    let few = format!("{frames} frames checked, not the 2,300 of 7 s at 333 Hz");
    report.conclude((frames < 2300).then_some(few))
}

/// The shipped Pico image (already built) for [`DEFAULT_TIME`]; fails unless
/// every check passes over at least [`MIN_FRAMES`] frames and the loops'
/// checksum is the host's. Returns the run for the memory stage.
pub fn test_pulses(root: &Path, metadata: &Metadata) -> Result<Report> {
    let (_, report) = checked_run(root, metadata, DEFAULT_TIME, WALL, |_| {})?;
    print!("{}{}", report.log_text(false), report.table());
    let mut problems = Vec::new();
    if report.frames() < MIN_FRAMES {
        problems.push(format!(
            "{} frames checked, fewer than {MIN_FRAMES}",
            report.frames()
        ));
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
) -> Result<(PathBuf, Report)> {
    let elf = shipped_image(root, metadata)?;
    let mut report = run::run_with(root, &elf, time, wall, setup)?;
    run::check(&mut report)?;
    Ok((elf, report))
}

/// Builds the drill image ([`build_drill`]), runs two of its boots (each 3 s of frames and the timeout) and checks the
/// reset and the soft start after it.
pub fn test_drill(root: &Path, metadata: &Metadata) -> Result<()> {
    let elf = build_drill(metadata)?;
    let mut report = run::run_with(root, &elf, Duration::from_millis(6_500), WALL, |_| {})?;
    run::check(&mut report)?;
    print!("{}{}", report.log_text(false), report.table());
    let mut problems = Vec::new();
    let says = |boot: usize, text: &str| report.boots.get(boot).is_some_and(|b| b.says(text));
    let mut want = |boot, text: &str, problem: &str| {
        if !says(boot, text) {
            problems.push(format!("boot {boot} did not log {problem}"));
        }
    };
    want(0, "boot: power-on", "a power-on boot");
    want(
        0,
        &format!("frames stop after frame {DRILL_FRAMES}"),
        "the drill's stop",
    );
    want(1, "last reset by the WATCHDOG", "the watchdog reset");
    want(
        1,
        "first frame: neutral pulses 1500 1500 1500 us",
        "neutral first pulses",
    );
    if !report.first()?.watchdog {
        problems.push("the watchdog did not reset the board after the frames stopped".to_owned());
    }
    for (b, boot) in report
        .boots
        .iter()
        .enumerate()
        .filter(|(_, boot)| boot.watchdog)
    {
        for (check, (name, ..)) in boot.servos.iter().zip(SERVOS) {
            // Frames 0..=DRILL_FRAMES, each its own pulse: neutral first and
            // the 2 s fade-in (checked against the host) before the stop.
            if check.fresh != DRILL_FRAMES + 1 {
                let want = DRILL_FRAMES + 1;
                problems.push(format!(
                    "boot {b}, {name}: {} frames went out, not {want}",
                    check.fresh
                ));
            }
            // The last duty is held until the reset, 100 ms: 5 periods.
            if check.held > 6 {
                problems.push(format!(
                    "boot {b}, {name}: {} pulses held before the reset",
                    check.held
                ));
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

/// Builds the shipped Pico image (`cargo build --release`, at once if it is
/// up to date) and returns its ELF.
pub fn shipped_image(root: &Path, metadata: &Metadata) -> Result<PathBuf> {
    PICO.build(root)?;
    Ok(PICO.elf(metadata))
}

/// Builds the drill image (`--features watchdog-drill`) and returns its ELF,
/// `target/watchdog-drill/…/pico`: the shipped ELF is never overwritten.
/// Its intermediate files stay in the one target directory
/// (`build.build-dir`), so it shares every dependency with the shipped
/// image and only the three crates the feature changes compile again.
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

/// Runs the shipped image with the UART and USB exchanges: fails if a
/// reply, a pulse or the run itself is wrong, or if its RAM (static plus
/// the measured peak stack) is over the budget.
pub fn test_console(
    root: &Path,
    metadata: &Metadata,
    virtual_time: Duration,
    wall: Duration,
) -> Result<()> {
    let (elf, mut report) = checked_run(root, metadata, virtual_time, wall, exchange::configure)?;
    exchange::check(&mut report);
    print!("{}", report.log_text(false));
    print!(
        "{}{}",
        report.exchange.as_deref().unwrap_or_default(),
        report.table()
    );
    report.conclude(console_ram(&elf, &report)?)
}

/// Prints the Pico image's RAM in `report`'s run, static plus the
/// measured peak stack; the problem if it is over the budget or the peak
/// was not measured.
pub fn console_ram(elf: &Path, report: &Report) -> Result<Option<String>> {
    let static_ram = elf::Image::read(elf)?.static_ram();
    let Some(stack) = report.peak_stack() else {
        let problem = "its peak stack was not measured";
        return Ok(Some(format!(
            "Pico image RAM: {static_ram} B static, but {problem}"
        )));
    };
    let (ram, budget) = (static_ram + stack, elf::RAM_BUDGET);
    let sum = format!("{ram} B (static {static_ram} B + peak stack {stack} B)");
    println!("Pico image RAM: {sum} of the {budget} B budget");
    Ok((ram > budget).then(|| format!("Pico image RAM {sum} is over the {budget} B budget")))
}

/// A hung image, an image that sleeps for ever, a run out of wall time and
/// files that are not Pico images: each ends with its own clear message.
pub fn test_failures(root: &Path, metadata: &Metadata) -> Result<()> {
    node::ensure(root)?;
    let dir = metadata.target_dir.join("sim-failures");
    std::fs::create_dir_all(&dir)?;
    // Thumb `b .` (a loop on itself) and `wfi`; the runs' virtual time,
    // wall time and silence.
    let (b_self, wfi) = (0xe7fe, 0xbf30);
    let (short, long) = (Duration::from_millis(50), Duration::from_secs(3600));
    let cases: [(&str, &[u16], [Duration; 3], &str); 3] = [
        (
            "hung",
            &[b_self],
            [Duration::from_secs(2), WALL, short],
            "no log byte and no pin edge",
        ),
        (
            "asleep",
            &[wfi, b_self],
            [Duration::from_secs(2), WALL, short],
            "sleeps with nothing left to wake it",
        ),
        (
            "slow",
            &[b_self],
            [long, Duration::from_millis(200), long],
            "stopped after",
        ),
    ];
    let mut problems = Vec::new();
    for (name, code, [virtual_time, wall, silence], want) in cases {
        let flash = dir.join(format!("{name}.bin"));
        std::fs::write(&flash, synthetic(code)).context("writing a test image")?;
        let vtor = VECTOR_TABLE;
        let config = node::Config {
            flash,
            vtor,
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
    let missing = dir.join("no-such-elf");
    for (path, want) in [
        (missing.as_path(), "cargo build --release"),
        (&std::env::current_exe()?, "is not a Pico image"),
    ] {
        match PicoImage::read(path) {
            Err(error) if format!("{error:#}").contains(want) => {
                println!("{}: {error:#}", path.display());
            }
            other => problems.push(format!(
                "{}: expected `{want}`, got {other:?}",
                path.display()
            )),
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
