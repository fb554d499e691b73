//! `cargo xtask test`: every check, as a list of stages that all run; the
//! command fails if any stage fails.

use std::{path::Path, time::Instant};

use anyhow::{Result, bail};

use xshell::cmd;

use crate::{
    args::Options,
    bench, book, console, elf, figures,
    log::Run,
    panel, pico2,
    project::{self, FIRMWARE_ENV, Metadata, PICO, QEMU},
    qemu::{self, Echo},
    setup, sim, snapshot,
};

/// Runs stages one after another and keeps score: each stage's name, its
/// error if it failed, and its seconds; and how many `--only` left out.
struct Stages<'a> {
    results: Vec<(String, Option<String>, f64)>,
    /// Only the stages whose name contains this run.
    only: Option<&'a str>,
    left_out: usize,
}

impl Stages<'_> {
    /// Runs one stage; `Ok(())` passes, an error fails it. A stage `--only`
    /// leaves out does not run, and counts as passed for what follows.
    fn run(&mut self, name: &str, stage: impl FnOnce() -> Result<()>) -> bool {
        if self.only.is_some_and(|only| !name.contains(only)) {
            self.left_out += 1;
            return true;
        }
        println!("\n==> {name}");
        let start = Instant::now();
        let failed = stage().err().map(|error| format!("{error:#}"));
        let seconds = start.elapsed().as_secs_f64();
        match &failed {
            None => println!("--- ok: {name} ({seconds:.1} s)"),
            Some(error) => println!("--- FAILED: {name}: {error}"),
        }
        self.results
            .push((name.to_owned(), failed.clone(), seconds));
        failed.is_none()
    }

    /// Records a stage that could not run because an earlier one failed.
    fn blocked(&mut self, name: &str, by: &str) {
        self.run(name, || bail!("not run, {by} failed"));
    }

    /// Prints the score card and the closing `N passed, M failed` line.
    fn finish(&self, start: Instant) -> bool {
        let failed = self.results.iter().filter(|(_, f, _)| f.is_some()).count();
        println!("\nstages:");
        for (name, failure, seconds) in &self.results {
            let verdict = if failure.is_some() { "FAILED" } else { "ok" };
            println!("  {verdict:<8} {seconds:>6.1} s  {name}");
        }
        for (name, failure, _) in &self.results {
            if let Some(error) = failure {
                println!("failed: {name}: {error}");
            }
        }
        println!("total time {:.0} s", start.elapsed().as_secs_f64().round());
        let left_out = match self.left_out {
            0 => String::new(),
            n => format!(" ({n} left out by --only)"),
        };
        println!(
            "{} passed, {failed} failed{left_out}",
            self.results.len() - failed
        );
        failed == 0
    }
}

/// `cargo xtask test`, all stages or `only` those whose name contains it.
/// `Ok(false)` when a stage failed.
pub fn command(options: Options, only: Option<&str>) -> Result<bool> {
    let start = Instant::now();
    let (root, metadata) = project::prepare()?;
    let sh = project::shell(".")?;
    let host_tests = project::shell("host-tests")?;
    let core = project::shell("crates/core")?;
    let firmware = project::shell("crates/firmware")?;
    let xtask = project::shell("xtask")?;
    let figures_page = root.join(figures::PAGE);
    let figures_before = figures::read(&figures_page)?;
    let mut stages = Stages {
        results: Vec::new(),
        only,
        left_out: 0,
    };

    // 1. Host tests of the core, the firmware layer and the project commands.
    stages.run("host tests (host-tests/)", || {
        project::run(&host_tests, &[], cmd!(host_tests, "cargo test"))
    });
    stages.run("core crate: unit and doc tests (crates/core, host)", || {
        project::run(&core, &[], cmd!(core, "cargo test"))
    });
    stages.run("firmware layer: host tests (crates/firmware)", || {
        project::run(&firmware, &[], cmd!(firmware, "cargo test"))
    });
    stages.run("xtask unit tests", || {
        project::run(&xtask, &[], cmd!(xtask, "cargo test --profile xtask"))
    });

    // 2. Formatting and lints: firmware (thumb, both packages) and host crates.
    stages.run("rustfmt: every package of the workspace", || {
        project::run(&sh, &[], cmd!(sh, "cargo fmt --all --check"))
    });
    clippy_stages(&mut stages);

    // 3. The Pico image: placement of the boot stage, memory budgets, no allocator.
    let pico_built = stages.run("Pico build (cargo build --release)", || PICO.build(&root));
    if pico_built {
        stages.run(
            "Pico image: .boot2 placement, memory budgets, no allocator",
            || elf::check_pico(&PICO.elf(&metadata)),
        );
    } else {
        stages.blocked(
            "Pico image: .boot2 placement, memory budgets, no allocator",
            "the Pico build",
        );
    }
    // The Pico 2 on its own: its embassy-rp chip feature excludes the Pico's.
    stages.run(pico2::STAGE, || pico2::test(&metadata));

    // The calibration image (same bin, feature `calibrate`): it must compile.
    stages.run(
        "Pico calibration image compiles (--features calibrate)",
        || {
            project::run(
                &sh,
                FIRMWARE_ENV,
                cmd!(sh, "cargo check --release --features calibrate"),
            )
        },
    );
    // A board with servos and USB only, on the same `start` as the Pico's.
    stages.run(
        "minimal board example, servos and USB only (examples/minimal.rs): clippy, build",
        || {
            let clippy = "clippy --release --example minimal -- -D warnings";
            let build = "build --release --example minimal";
            for args in [clippy, build] {
                let args = args.split_whitespace();
                project::run(&sh, FIRMWARE_ENV, cmd!(sh, "cargo {args...}"))?;
            }
            Ok(())
        },
    );
    // The frame path cannot panic: this image links the frame update against
    // a panic handler that does not exist, so the link fails if any panic
    // path survives optimisation (boards/qemu/src/panic_proof.rs).
    stages.run(
        "frame path has no panic path (link of frame-path-proof)",
        || project::Image::qemu("frame-path-proof").build(&root),
    );

    // 4. The QEMU run against the log on file, and the firmware's own verdict.
    let qemu_run = qemu_stages(&mut stages, &root, &metadata, options);

    // The Pico image in the RP2040 emulator, the watchdog drill, and its RAM
    // with the peak stack measured there.
    sim_stages(&mut stages, &root, &metadata, pico_built, qemu_run.as_ref());

    // 5. The boot-time benchmark in QEMU and the default set's instruction
    // budget; its telemetry check compares against the QEMU run above.
    stages.run(bench::tracking::STAGE, bench::tracking::stage);
    stages.run(bench::LATENCY_STAGE, || {
        bench::latency_stage(&root, &metadata)
    });
    stages.run(bench::STAGE, || {
        setup::ensure_qemu()?;
        bench::run_and_check(&root, &metadata, options, qemu_run.as_ref())
    });

    // The panel in a real browser (Chromium, headless).
    stages.run(panel::browser::STAGE, || {
        println!("{}", panel::browser::stage(&root, &metadata)?);
        Ok(())
    });

    // 6. The book, with the figures measured above, and its links.
    stages.run(book::STAGE, || book::stage(&root));
    stages.run(figures::STAGE, || {
        figures::stale(&figures_page, &figures_before)
    });

    Ok(stages.finish(start))
}

/// The clippy passes: the firmware's (thumbv6m, `--release` to share build
/// scripts and proc-macros with the release builds), the Pico 2's, and the
/// host crates'; `(name, folder, firmware, arguments)`.
const CLIPPY: [(&str, &str, bool, &str); 7] = [
    (
        "clippy: Pico image, RP support, firmware layer, core (thumbv6m)",
        ".",
        true,
        "--release --package idle-head --package idle-head-rp --package idle-head-firmware \
         --package idle-head-core",
    ),
    (
        "clippy: QEMU images, boards/qemu/ (thumbv6m)",
        ".",
        true,
        "--release --bins --package idle-head-qemu",
    ),
    (
        "clippy: Pico 2 image, boards/pico2/ (thumbv8m.main)",
        "boards/pico2",
        true,
        "--release",
    ),
    (
        "clippy: core crate and its unit tests (host)",
        ".",
        false,
        "--package idle-head-core --all-targets --target host-tuple",
    ),
    (
        "clippy: firmware layer and its unit tests (host)",
        ".",
        false,
        "--package idle-head-firmware --all-targets --target host-tuple",
    ),
    ("clippy: host-tests", "host-tests", false, "--all-targets"),
    ("clippy: xtask", "xtask", false, "--all-targets"),
];

fn clippy_stages(stages: &mut Stages<'_>) {
    for (name, dir, firmware, args) in CLIPPY {
        stages.run(name, || {
            let sh = project::shell(dir)?;
            let args = args.split_whitespace();
            let env = if firmware { FIRMWARE_ENV } else { &[] };
            project::run(&sh, env, cmd!(sh, "cargo clippy {args...} -- -D warnings"))
        });
    }
}

fn sim_stages(
    stages: &mut Stages<'_>,
    root: &Path,
    metadata: &Metadata,
    pico_built: bool,
    qemu_run: Option<&Run>,
) {
    const MEMORY: &str = "RAM: static + peak stack of the Pico image within its budget";
    let mut report = None;
    if pico_built {
        stages.run(sim::PULSES_STAGE, || {
            report = Some(sim::test_pulses(root, metadata)?);
            Ok(())
        });
    } else {
        stages.blocked(sim::PULSES_STAGE, "the Pico build");
    }
    stages.run(sim::RATE_STAGE, || sim::test_rate(root, metadata));
    stages.run(sim::DRILL_STAGE, || sim::test_drill(root, metadata));
    stages.run(sim::INPUTS_STAGE, || sim::test_inputs(root, metadata));
    stages.run(sim::CONSOLE_STAGE, || {
        sim::test_console(root, metadata, sim::CONSOLE_TIME, sim::WALL)
    });
    stages.run(sim::STORE_STAGE, || sim::test_store(root, metadata));
    stages.run(sim::NOISE_STAGE, || sim::test_noise(root, metadata));
    stages.run(sim::FLOOD_STAGE, || sim::test_flood(root, metadata));
    stages.run(sim::UART_STREAM_STAGE, || {
        sim::test_stream(root, metadata, "uart", sim::STREAM_LENGTH)
    });
    stages.run(sim::USB_STREAM_STAGE, || {
        sim::test_stream(root, metadata, "usb", sim::STREAM_LENGTH)
    });
    stages.run(sim::DMX_STREAM_STAGE, || sim::test_dmx(root, metadata));
    stages.run(sim::FAILURES_STAGE, || sim::test_failures(root, metadata));
    stages.run(sim::SHOW_STAGE, || sim::test_show(root, metadata));
    stages.run(sim::RADAR_STAGE, || sim::test_radar(root, metadata));
    stages.run(sim::RADAR_DMX_STAGE, || sim::test_radar_dmx(root, metadata));
    stages.run(MEMORY, || {
        let peak = |elf: &Path, stack: Option<u64>| -> Result<Option<elf::Peak>> {
            let Some(stack) = stack else { return Ok(None) };
            let static_ram = elf::Image::read(elf)?.static_ram();
            Ok(Some(elf::Peak { static_ram, stack }))
        };
        let pico = peak(
            &PICO.elf(metadata),
            report.as_ref().and_then(sim::Report::peak_stack),
        )?;
        let qemu_peak = qemu_run.and_then(|run| sim::logged_peak_stack(&run.log));
        let qemu = peak(&QEMU.elf(metadata), qemu_peak)?;
        elf::check_ram(pico, qemu)
    });
}

fn qemu_stages(
    stages: &mut Stages<'_>,
    root: &Path,
    metadata: &Metadata,
    options: Options,
) -> Option<Run> {
    const BUILD: &str = "QEMU build (LM3S6965 memory map, no allocator linked)";
    const RUN: &str = "QEMU run: firmware exits with success";
    const SNAPSHOT: &str = "QEMU log matches boards/qemu/expected.log";
    const SUMMARY: &str = "QEMU summary: missed=0 pulse_violations=0, checksum = host's";
    const CONSOLE: &str = "cargo xtask console --qemu with a piped script";

    let built = stages.run(BUILD, || {
        setup::ensure_qemu()?;
        QEMU.build(root)?;
        elf::check_qemu(&QEMU.elf(metadata))
    });
    if !built {
        for name in [RUN, SNAPSHOT, SUMMARY] {
            stages.blocked(name, BUILD);
        }
        return None;
    }
    let mut run: Option<Run> = None;
    stages.run(RUN, || {
        let done = qemu::run(&QEMU.elf(metadata), options.timeout, Echo::Problems)?;
        println!("{}", done.describe());
        let succeeded = done.succeeded();
        let describe = done.describe();
        run = Some(done);
        if succeeded {
            Ok(())
        } else {
            bail!("{describe}")
        }
    });
    let Some(run) = run else {
        for name in [SNAPSHOT, SUMMARY] {
            stages.blocked(name, RUN);
        }
        return None;
    };
    stages.run(SNAPSHOT, || {
        if options.bless {
            if !run.succeeded() {
                bail!("not re-recording the expected log: the run failed");
            }
            snapshot::bless(&run)
        } else {
            snapshot::compare(&run, &metadata.target_dir.join("qemu-actual.log"))
        }
    });
    stages.run(CONSOLE, || {
        println!("{}", console::piped_script()?);
        Ok(())
    });
    stages.run(SUMMARY, || {
        if let Some(line) = run
            .log
            .iter()
            .rev()
            .find(|line| line.message.starts_with("summary"))
        {
            println!("{}", line.snapshot());
        }
        let verdict = qemu::check_summary(&run.log)?;
        println!("{verdict}");
        qemu::record_figures(&run.log);
        Ok(())
    });
    Some(run)
}
