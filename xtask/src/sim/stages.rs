//! The emulator's stages of `cargo xtask test`.

use std::{
    path::{Path, PathBuf},
    time::Duration,
};

use anyhow::{Context, Result, bail};

use super::{
    DEFAULT_TIME, harness,
    image::{FLASH_START, PicoImage, VECTOR_TABLE},
    node,
    run::{self, Report},
};
use xshell::cmd;

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
/// (`DRILL_FRAMES` in `src/bin/pico/main.rs`).
const DRILL_FRAMES: usize = 150;
/// The Pico's watchdog timeout (`WATCHDOG_TIMEOUT` in `src/bin/pico/main.rs`).
const WATCHDOG_MS: f64 = 100.0;
/// Two drill boots: each 3 s of frames and the 100 ms timeout.
const DRILL_TIME: Duration = Duration::from_millis(6_500);
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
/// [`RATE_SCRIPT`] played into it; every pulse checked against the host
/// trace at 333 Hz (its 3003 µs period, 60 060 counts of 50 ns).
pub fn test_rate(root: &Path, metadata: &Metadata) -> Result<()> {
    let events = super::script::parse(RATE_SCRIPT)?;
    let rate = idle_head_core::servo::ServoRate::MAX;
    let time = Duration::from_secs(7);
    let board = super::script::Board { rate, uid: None };
    let report = super::script::play_at(
        root,
        metadata,
        events,
        time,
        WALL,
        super::script::Against::Host,
        board,
    )?;
    print!("{}", report.table());
    println!("{}", report.verdict());
    let frames = report.boots.first().map_or(0, |boot| boot.servos[0].frames);
    // 7 s at 3003 µs, from the first frame.
    if frames < 2300 {
        bail!("{frames} frames checked, not the 2,300 of 7 s at 333 Hz");
    }
    if report.problems.is_empty() {
        Ok(())
    } else {
        bail!("{}", report.problems.join("; "))
    }
}

/// The shipped Pico image (already built) for [`DEFAULT_TIME`]; fails unless
/// every check passes over at least [`MIN_FRAMES`] frames and the loops'
/// checksum is the host's. Returns the run for the memory stage.
pub fn test_pulses(root: &Path, metadata: &Metadata) -> Result<Report> {
    let report = run::simulate(root, &PICO.elf(metadata), DEFAULT_TIME, WALL, false)?;
    print!("{}", report.log_text(false));
    print!("{}", report.table());
    println!("{}", report.verdict());
    println!("{}", report.summary());
    let mut problems = report.problems.clone();
    if report.frames() < MIN_FRAMES {
        problems.push(format!(
            "{} frames checked, fewer than {MIN_FRAMES}",
            report.frames()
        ));
    }
    if report.watchdog_resets() > 0 {
        problems.push("the watchdog reset the shipped image".to_owned());
    }
    let host = reference::checksum()?;
    let want = format!("checksum {host:#010x}");
    let logged = report
        .boots
        .iter()
        .flat_map(|b| &b.log)
        .any(|(_, l)| l.message.contains(&want));
    if !logged {
        problems.push(format!(
            "no `precompute: ...; {want}` line, the host's checksum"
        ));
    }
    fail_if_any(&problems)?;
    Ok(report)
}

/// Builds the drill image (`--features watchdog-drill`, in a target
/// directory of its own so that the shipped ELF is never overwritten), runs
/// two of its boots and checks the reset and the soft start after it.
pub fn test_drill(root: &Path, metadata: &Metadata) -> Result<()> {
    let elf = build_variant(root, metadata, "watchdog-drill")?;
    let report = run::simulate(root, &elf, DRILL_TIME, WALL, false)?;
    print!("{}", report.log_text(false));
    print!("{}", report.table());
    println!("{}", report.verdict());
    println!("{}", report.summary());

    let mut problems = report.problems.clone();
    let says = |boot: usize, text: &str| {
        report
            .boots
            .get(boot)
            .is_some_and(|b| b.log.iter().any(|(_, l)| l.message.contains(text)))
    };
    let first = report.boots.first().context("no boot at all")?;
    if !first.watchdog {
        problems.push("the watchdog did not reset the board after the frames stopped".to_owned());
    }
    if !says(0, "boot: power-on") || !says(0, &format!("frames stop after frame {DRILL_FRAMES}")) {
        problems.push("boot 0 did not log a power-on boot and the drill's stop".to_owned());
    }
    if !says(1, "last reset by the WATCHDOG") {
        problems.push("boot 1 did not log the watchdog reset".to_owned());
    }
    if !says(1, "first frame: neutral pulses 1500 1500 1500 us") {
        problems.push("boot 1 did not log neutral first pulses".to_owned());
    }
    for (b, boot) in report
        .boots
        .iter()
        .enumerate()
        .filter(|(_, boot)| boot.watchdog)
    {
        for (check, (name, ..)) in boot.servos.iter().zip(harness::SERVOS) {
            // Frames 0..=DRILL_FRAMES, each its own pulse: neutral first and
            // the 2 s fade-in (checked against the host) before the stop.
            if check.fresh != DRILL_FRAMES + 1 {
                problems.push(format!(
                    "boot {b}, {name}: {} frames went out, not {}",
                    check.fresh,
                    DRILL_FRAMES + 1
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
    fail_if_any(&problems)
}

/// Builds the shipped Pico image (`cargo build --release`, at once if it is
/// up to date) and returns its ELF.
pub fn shipped_image(root: &Path, metadata: &Metadata) -> Result<PathBuf> {
    PICO.build(root)?;
    Ok(PICO.elf(metadata))
}

/// Builds the Pico image with `feature` in a target directory of its own
/// (`target/<feature>`), so that the shipped ELF is never overwritten;
/// returns its ELF.
pub fn build_variant(root: &Path, metadata: &Metadata, feature: &str) -> Result<PathBuf> {
    let target = metadata.target_dir.join(feature);
    let sh = project::shell(".")?;
    sh.change_dir(root);
    project::run(
        &sh,
        project::FIRMWARE_ENV,
        cmd!(
            sh,
            "cargo build --release --features {feature} --target-dir {target}"
        ),
    )?;
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
    let elf = shipped_image(root, metadata)?;
    let report = run::simulate(root, &elf, virtual_time, wall, true)?;
    print!("{}", report.log_text(false));
    print!("{}", report.exchange.as_deref().unwrap_or_default());
    print!("{}", report.table());
    println!("{}", report.verdict());
    println!("{}", report.summary());
    let mut problems = report.problems.clone();
    problems.extend(console_ram(&elf, &report)?);
    fail_if_any(&problems)
}

/// Prints the Pico image's RAM in `report`'s run, static plus the
/// measured peak stack; the problem if it is over the budget or the peak
/// was not measured.
pub fn console_ram(elf: &Path, report: &Report) -> Result<Option<String>> {
    let static_ram = elf::Image::read(elf)?.static_ram();
    let Some(stack) = report.peak_stack() else {
        return Ok(Some(format!(
            "Pico image RAM: {static_ram} B static, but its peak stack was not measured"
        )));
    };
    let ram = static_ram + stack;
    println!(
        "Pico image RAM: {static_ram} B static + {stack} B peak stack = {ram} B of the {} B budget",
        elf::RAM_BUDGET
    );
    Ok((ram > elf::RAM_BUDGET).then(|| {
        format!(
            "Pico image RAM {ram} B (static {static_ram} B + peak stack {stack} B) is over the {} B budget",
            elf::RAM_BUDGET
        )
    }))
}

/// A hung image, an image that sleeps for ever, a run out of wall time and
/// files that are not Pico images: each ends with its own clear message.
pub fn test_failures(root: &Path, metadata: &Metadata) -> Result<()> {
    node::ensure(root)?;
    let dir = metadata.target_dir.join("sim-failures");
    std::fs::create_dir_all(&dir)?;
    let cases: [(&str, &[u16], Duration, &str); 3] = [
        ("hung", &[B_SELF], WALL, "no log byte and no pin edge"),
        (
            "asleep",
            &[WFI, B_SELF],
            WALL,
            "sleeps with nothing left to wake it",
        ),
        (
            "slow",
            &[B_SELF],
            Duration::from_millis(200),
            "stopped after",
        ),
    ];
    let mut problems = Vec::new();
    for (name, code, wall, want) in cases {
        let flash = dir.join(format!("{name}.bin"));
        std::fs::write(&flash, synthetic(code))?;
        let silence = if name == "slow" {
            Duration::from_secs(3600)
        } else {
            Duration::from_millis(50)
        };
        let config = node::Config {
            flash,
            vtor: VECTOR_TABLE,
            virtual_time: Duration::from_secs(if name == "slow" { 3600 } else { 2 }),
            wall,
            silence,
            ..node::Config::default()
        };
        let events = node::run(root, &config)?;
        let end = run::end_of(&events)?;
        match end.problem(silence) {
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
    fail_if_any(&problems)
}

/// Thumb `b .`: a loop on itself.
const B_SELF: u16 = 0xe7fe;
/// Thumb `wfi`.
const WFI: u16 = 0xbf30;

/// A flash image: 256 bytes where boot2 would be, a vector table (stack at
/// the top of RAM, reset handler right behind it) and `code`.
fn synthetic(code: &[u16]) -> Vec<u8> {
    let mut flash = vec![0xff; usize::try_from(VECTOR_TABLE - FLASH_START).unwrap_or(0x100)];
    #[allow(clippy::cast_possible_truncation)] // addresses of the RP2040, 32 bits
    let reset = (VECTOR_TABLE + 8) as u32 | 1;
    flash.extend(0x2004_0000_u32.to_le_bytes());
    flash.extend(reset.to_le_bytes());
    flash.extend(code.iter().flat_map(|half| half.to_le_bytes()));
    flash
}

/// Prints `report`'s verdict and summary and a scenario's own `text`;
/// fails with the run's problems and the scenario's `found`, if any.
pub fn conclude(report: &Report, (text, found): (String, Vec<String>)) -> Result<()> {
    println!("{}", report.verdict());
    println!("{}", report.summary());
    print!("{text}");
    let problems: Vec<String> = report.problems.iter().cloned().chain(found).collect();
    fail_if_any(&problems)
}

fn fail_if_any(problems: &[String]) -> Result<()> {
    if problems.is_empty() {
        Ok(())
    } else {
        bail!("{}", problems.join("; "))
    }
}
