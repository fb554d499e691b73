//! `cargo xtask test`: every check, as a list of stages that all run; the
//! command fails if any stage fails.

use std::{path::Path, time::Instant};

use anyhow::{Result, bail, ensure};

use xshell::cmd;

use crate::{
    args::Options,
    bench, book, console, elf, figures,
    log::{self, Run},
    panel::browser,
    pico2,
    project::{self, FIRMWARE_ENV, LINTED, Metadata, PICO, QEMU},
    qemu::{self, Echo},
    setup, sim, snapshot,
};

/// The score: each stage's name, its error if it failed, its seconds; and
/// how many `--only` left out.
struct Stages<'a> {
    results: Vec<(String, Option<String>, f64)>,
    /// Only the stages whose name contains this run.
    only: Option<&'a str>,
    left_out: usize,
}

impl Stages<'_> {
    /// Runs one stage unless `--only` leaves it out (it then counts as
    /// passed for what follows).
    fn run(&mut self, name: &str, stage: impl FnOnce() -> Result<()>) -> bool {
        self.run_if(false, name, stage)
    }

    /// [`Stages::run`], also when `--only` leaves it out if `needed`.
    fn run_if(&mut self, needed: bool, name: &str, stage: impl FnOnce() -> Result<()>) -> bool {
        if !needed && !self.chosen(name) {
            self.left_out += 1;
            return true;
        }
        println!("\n==> {name}");
        let start = Instant::now();
        let failed = stage().err().map(|error| format!("{error:#}"));
        self.score(name, failed, start.elapsed().as_secs_f64())
    }

    /// Whether `--only` lets the stage `name` run.
    fn chosen(&self, name: &str) -> bool {
        self.only.is_none_or(|only| name.contains(only))
    }

    /// Prints the output of a stage run apart ([`run_apart`]), and scores it.
    fn record(&mut self, name: &str, (output, failed, seconds): Outcome) {
        println!("\n==> {name}");
        let _ = std::io::Write::write_all(&mut std::io::stdout(), &output);
        self.score(name, failed, seconds);
    }

    fn score(&mut self, name: &str, failed: Option<String>, seconds: f64) -> bool {
        match &failed {
            None => println!("--- ok: {name} ({seconds:.1} s)"),
            Some(error) => println!("--- FAILED: {name}: {error}"),
        }
        let passed = failed.is_none();
        self.results.push((name.to_owned(), failed, seconds));
        passed
    }

    /// Fails the stages `names`, which cannot run because `by` failed.
    fn blocked(&mut self, names: &[&str], by: &str) {
        for name in names {
            self.run(name, || bail!("not run, {by} failed"));
        }
    }

    /// Prints the score card and `N passed, M failed`.
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
        let passed = self.results.len() - failed;
        println!("{passed} passed, {failed} failed{left_out}");
        failed == 0
    }
}

/// `cargo xtask test`, all stages or `only` those whose name contains it.
/// `Ok(false)` when a stage failed.
pub fn command(options: Options, only: Option<&str>) -> Result<bool> {
    const PICO_IMAGE: &str = "Pico image: .boot2 placement, memory budgets, no allocator";
    const DRILL_BUILD: &str =
        "watchdog drill image (cargo build --release --features watchdog-drill)";
    let start = Instant::now();
    let (root, metadata) = setup::prepare()?;
    project::keep_exe(&metadata.target_dir.join("xtask-stages"))?;
    let figures_page = root.join(figures::PAGE);
    let figures_before = figures::read(&figures_page)?;
    let mut stages = Stages {
        results: Vec::new(),
        only,
        left_out: 0,
    };

    // 1. The Pico image and the watchdog drill's: the emulator stages run on
    // them in the background, at a low priority, while the stages below take
    // the cores first (their links and waits leave a core idle at times).
    let emulated = (APART.iter()).any(|(name, _)| needs_image(name) && stages.chosen(name));
    let pico_built = stages.run_if(emulated, "Pico build (cargo build --release)", || {
        PICO.build(&root)
    });
    if pico_built {
        stages.run(PICO_IMAGE, || elf::check_pico(&PICO.elf(&metadata)));
    } else {
        stages.blocked(&[PICO_IMAGE], "the Pico build");
    }
    let drill = stages.chosen(sim::DRILL_STAGE);
    let drill_built = stages.run_if(drill, DRILL_BUILD, || sim::build_drill(&metadata).map(drop));
    let _ = std::fs::remove_file(peak_file(&metadata));
    std::thread::scope(|scope| {
        let background = Background::start(scope, &stages, &root, pico_built, drill_built);

        // 2. Host tests, formatting, lints, the images that must compile.
        for (name, dir, env, commands) in CARGO {
            stages.run(name, || {
                let sh = project::shell(dir)?;
                for args in commands.split(" && ") {
                    let args = args.split_whitespace();
                    project::run(&sh, env, cmd!(sh, "cargo {args...}"))?;
                }
                Ok(())
            });
        }
        // The Pico 2 on its own: its embassy-rp chip feature excludes the Pico's.
        stages.run(pico2::STAGE, || pico2::test(&metadata));

        // The link fails if a panic path survives (boards/qemu/src/panic_proof.rs).
        stages.run(
            "frame path has no panic path (link of frame-path-proof)",
            || project::Image::qemu("frame-path-proof").build(&root),
        );

        // 3. The QEMU run against the log on file, and the firmware's own verdict.
        let qemu_run = qemu_stages(&mut stages, &root, &metadata, options);

        // 4. The boot-time benchmark in QEMU and the default set's instruction
        // budget; its telemetry check compares against the QEMU run above.
        stages.run(bench::tracking::STAGE, bench::tracking::stage);
        stages.run(bench::STAGE, || {
            setup::ensure_qemu()?;
            bench::run_and_check(&root, &metadata, options, qemu_run.as_ref())
        });

        // 5. The host tests, the book and the emulator stages' results (all
        // run in the background), and the RAM with the peak stack measured
        // in the emulator.
        background.record(&mut stages, &metadata, qemu_run.as_ref());
    });
    // The panel in a real browser (Chromium, headless), with the cores to
    // itself: beside the emulator stages, the page once waited more than the
    // 3 s it allows for a reply from the QEMU image it is bridged to.
    stages.run(browser::STAGE, || browser::stage(&root, &metadata));
    stages.run(figures::STAGE, || {
        figures::stale(&figures_page, &figures_before)
    });

    Ok(stages.finish(start))
}

/// The stages that run cargo, `(name, folder, environment, commands)`: the
/// firmware's with its build environment (and `--release`, to share build
/// scripts with the release builds), the host's builds linted as they compile
/// ([`LINTED`]: clippy with `-D warnings`, on every target `cargo clippy
/// --all-targets` lints: a library, its tests, the doc tests' library), the
/// commands' arguments separated by ` && `.
#[rustfmt::skip] // a table, one stage a line
const CARGO: [(&str, &str, project::Env, &str); 10] = [
    // Built here, at full priority: their run is a background stage.
    ("host tests: build, clippy (host-tests/)", "host-tests", LINTED, "test --no-run"),
    ("core crate: clippy, unit and doc tests (crates/core, host)", "crates/core", LINTED, "test"),
    ("firmware layer: clippy, host tests (crates/firmware)", "crates/firmware", LINTED, "test"),
    ("xtask: clippy, unit tests", "xtask", LINTED,
     "build --profile xtask --all-targets && test --profile xtask"),
    ("rustfmt: every package of the workspace", ".", &[], "fmt --all --check"),
    ("clippy: Pico image, RP support, firmware layer, core (thumbv6m)", ".", FIRMWARE_ENV,
     "clippy --release --package idle-head --package idle-head-rp --package idle-head-firmware \
      --package idle-head-core -- -D warnings"),
    ("clippy: QEMU images, boards/qemu/ (thumbv6m)", ".", FIRMWARE_ENV,
     "clippy --release --bins --package idle-head-qemu -- -D warnings"),
    ("clippy: Pico 2 image, boards/pico2/ (thumbv8m.main)", "boards/pico2", FIRMWARE_ENV,
     "clippy --release -- -D warnings"),
    // The calibration image (same bin, feature `calibrate`) must compile.
    ("Pico calibration image compiles (--features calibrate)", ".", FIRMWARE_ENV,
     "check --release --features calibrate"),
    // A board with servos and USB only, on the same `start` as the Pico's.
    ("minimal board example, servos and USB only (examples/minimal.rs): clippy, build", ".",
     FIRMWARE_ENV,
     "clippy --release --example minimal -- -D warnings && build --release --example minimal"),
];

/// A stage run apart: its name, and what it runs.
type Apart = (&'static str, fn(&Path, &Metadata) -> Result<()>);

/// The host tests' run: built in the foreground, run in the background
/// (`cargo test` holds no cargo lock while its tests run).
const HOST_TESTS: &str = "host tests (host-tests/)";

/// Whether the background stage `name` runs on the Pico images: all but the
/// host tests' run and the book (mdBook installs into its own folder).
fn needs_image(name: &str) -> bool {
    name != HOST_TESTS && name != book::STAGE
}

/// The stages run side by side in the background (`cargo xtask test
/// --stage NAME`), in the order of the score card: the host tests, the
/// book, then the ones in the RP2040 emulator, on images built already.
/// [`Background::start`] starts the longest first. Only the latency stage
/// records figures.
const APART: [Apart; 18] = [
    (HOST_TESTS, |_, _| {
        let sh = project::shell("host-tests")?;
        project::run(&sh, LINTED, cmd!(sh, "cargo test"))
    }),
    (book::STAGE, |root, _| book::stage(root)),
    (sim::PULSES_STAGE, |root, metadata| {
        let report = sim::test_pulses(root, metadata)?;
        let stack = report.peak_stack().map(|s| s.to_string());
        project::write(&peak_file(metadata), stack.unwrap_or_default())
    }),
    (sim::RATE_STAGE, sim::test_rate),
    (sim::DRILL_STAGE, sim::test_drill),
    (sim::INPUTS_STAGE, sim::test_inputs),
    (sim::CONSOLE_STAGE, |root, metadata| {
        sim::test_console(root, metadata, sim::CONSOLE_TIME, sim::WALL)
    }),
    (sim::STORE_STAGE, sim::test_store),
    (sim::NOISE_STAGE, sim::test_noise),
    (sim::FLOOD_STAGE, sim::test_flood),
    (sim::UART_STREAM_STAGE, |root, metadata| {
        sim::test_stream(root, metadata, "uart", sim::STREAM_LENGTH)
    }),
    (sim::USB_STREAM_STAGE, |root, metadata| {
        sim::test_stream(root, metadata, "usb", sim::STREAM_LENGTH)
    }),
    (sim::DMX_STREAM_STAGE, sim::test_dmx),
    (sim::FAILURES_STAGE, sim::test_failures),
    (sim::SHOW_STAGE, sim::test_show),
    (sim::RADAR_STAGE, sim::test_radar),
    (sim::RADAR_DMX_STAGE, sim::test_radar_dmx),
    (bench::LATENCY_STAGE, bench::latency_stage),
];

/// Where the pulses stage leaves its peak stack for the RAM stage.
fn peak_file(metadata: &Metadata) -> std::path::PathBuf {
    metadata.target_dir.join("sim-pulses-peak-stack")
}

/// `cargo xtask test --stage NAME`: one of [`APART`], on images built
/// already.
pub fn stage(name: &str) -> Result<bool> {
    let Some((_, run)) = APART.iter().find(|(stage, _)| *stage == name) else {
        bail!("no emulator stage is called `{name}`");
    };
    let root = project::root();
    run(&root, &project::metadata(&root)?)?;
    Ok(true)
}

/// A stage run apart: its output (stdout and stderr), error, seconds.
type Outcome = (Vec<u8>, Option<String>, f64);

/// Runs `xtask test --stage name`, [`project::PREBUILT`] set to `cores`.
fn run_apart(name: &str, cores: usize) -> Outcome {
    let start = Instant::now();
    let run = || -> Result<(Vec<u8>, std::process::ExitStatus)> {
        let (mut reader, writer) = std::io::pipe()?;
        // At a low priority where `nice` exists: the stages in the foreground
        // take the cores first.
        let (exe, nice) = (project::exe()?, which::which("nice").ok());
        let mut command = std::process::Command::new(nice.as_ref().unwrap_or(&exe));
        if nice.is_some() {
            command.args(["-n", "10"]).arg(exe);
        }
        command
            .args(["test", "--stage", name])
            .env(project::PREBUILT, cores.to_string())
            .stdin(std::process::Stdio::null());
        let mut child = command.stdout(writer.try_clone()?).stderr(writer).spawn()?;
        drop(command);
        let mut output = Vec::new();
        std::io::Read::read_to_end(&mut reader, &mut output)?;
        Ok((output, child.wait()?))
    };
    let (output, failed) = match run() {
        Ok((output, status)) if status.success() => (output, None),
        Ok((output, status)) => {
            let text = String::from_utf8_lossy(&output);
            let error = text.lines().rev().find_map(|l| l.strip_prefix("error: "));
            let error = error.map_or_else(|| status.to_string(), str::to_owned);
            (output, Some(error))
        }
        Err(error) => (Vec::new(), Some(format!("starting it: {error:#}"))),
    };
    (output, failed, start.elapsed().as_secs_f64())
}

/// The stages of [`APART`], side by side in the background; their results
/// are scored in order by [`Background::record`].
struct Background {
    /// The chosen stages' indices in [`APART`], each with what keeps it
    /// from running, if anything.
    chosen: Vec<(usize, Option<&'static str>)>,
    results: std::sync::mpsc::Receiver<(usize, Outcome)>,
}

impl Background {
    /// Starts one worker a core on `scope`, longest stages first.
    fn start<'scope>(
        scope: &'scope std::thread::Scope<'scope, '_>,
        stages: &Stages<'_>,
        root: &Path,
        pico_built: bool,
        drill_built: bool,
    ) -> Self {
        let chosen: Vec<usize> = (0..APART.len())
            .filter(|&i| stages.chosen(APART[i].0))
            .collect();
        let cannot = |error: &anyhow::Error| println!("the emulator cannot run: {error:#}");
        let emulated = chosen.iter().any(|&i| needs_image(APART[i].0));
        let node = !emulated || sim::node::ensure(root).inspect_err(cannot).is_ok();
        let blocked = |i: usize| {
            if !needs_image(APART[i].0) {
                None
            } else if !pico_built {
                Some("the Pico build")
            } else if !node {
                Some("the emulator's setup")
            } else if APART[i].0 == sim::DRILL_STAGE && !drill_built {
                Some("the drill image's build")
            } else {
                None
            }
        };
        let chosen: Vec<_> = chosen.into_iter().map(|i| (i, blocked(i))).collect();
        // Longest first (the host tests are built in the foreground by then).
        let mut queue: Vec<usize> = (chosen.iter())
            .filter_map(|&(i, by)| by.is_none().then_some(i))
            .collect();
        let long = [
            bench::LATENCY_STAGE,
            sim::UART_STREAM_STAGE,
            sim::USB_STREAM_STAGE,
            HOST_TESTS,
            sim::DMX_STREAM_STAGE,
            book::STAGE,
        ];
        let rank = |i: &usize| long.iter().position(|name| *name == APART[*i].0);
        queue.sort_by_key(|i| rank(i).unwrap_or(long.len()));
        let queue = std::sync::Arc::new(std::sync::Mutex::new(queue.into_iter()));
        let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
        let (sender, results) = std::sync::mpsc::channel();
        for _ in 0..cores {
            let (sender, queue) = (sender.clone(), queue.clone());
            scope.spawn(move || {
                while let Some(i) = queue.lock().ok().and_then(|mut q| q.next()) {
                    let _ = sender.send((i, run_apart(APART[i].0, cores)));
                }
            });
        }
        Self { chosen, results }
    }

    /// Scores each stage in order as soon as those before it are, then the
    /// RAM with the peak stack measured in the pulses stage.
    fn record(self, stages: &mut Stages<'_>, metadata: &Metadata, qemu_run: Option<&Run>) {
        const MEMORY: &str = "RAM: static + peak stack of the Pico image within its budget";
        let mut done: Vec<Option<Outcome>> = vec![None; APART.len()];
        for &(i, blocked) in &self.chosen {
            if let Some(by) = blocked {
                stages.blocked(&[APART[i].0], by);
                continue;
            }
            while done[i].is_none() {
                let Ok((j, outcome)) = self.results.recv() else {
                    break;
                };
                done[j] = Some(outcome);
            }
            let lost = || (Vec::new(), Some("its worker stopped".to_owned()), 0.0);
            stages.record(APART[i].0, done[i].take().unwrap_or_else(lost));
        }
        stages.left_out += APART.len() - self.chosen.len();
        stages.run(MEMORY, || {
            let stack = std::fs::read_to_string(peak_file(metadata)).ok();
            let stack = stack.and_then(|s| s.trim().parse().ok());
            let qemu = qemu_run.and_then(|run| sim::logged_peak_stack(&run.log));
            elf::check_ram((&PICO.elf(metadata), stack), (&QEMU.elf(metadata), qemu))
        });
    }
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

    let image = QEMU.elf(metadata);
    let built = stages.run(BUILD, || {
        setup::ensure_qemu()?;
        QEMU.build(root)?;
        elf::check_qemu(&image)
    });
    if !built {
        stages.blocked(&[CONSOLE, RUN, SNAPSHOT, SUMMARY], BUILD);
        return None;
    }
    // It needs the image only (so `--only console` runs it too).
    stages.run(CONSOLE, console::piped_script);
    let mut run: Option<Run> = None;
    stages.run(RUN, || {
        let done = run.insert(qemu::run(&image, options.timeout, Echo::Problems)?);
        println!("{}", done.describe());
        ensure!(done.succeeded(), "{}", done.describe());
        Ok(())
    });
    let Some(run) = run else {
        stages.blocked(&[SNAPSHOT, SUMMARY], RUN);
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
    stages.run(SUMMARY, || {
        if let Some(line) = log::summary(&run.log) {
            println!("{line}");
        }
        let verdict = qemu::check_summary(&run.log)?;
        println!("{verdict}");
        qemu::record_figures(&run.log);
        Ok(())
    });
    Some(run)
}
