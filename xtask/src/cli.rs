//! The command line: every command and its options (clap). The option groups
//! that several commands share are in `args.rs`.

use std::time::Duration;

use clap::{Parser, Subcommand};

use crate::{
    args::{Bless, Budget, Options, Timeout},
    console, flash, metrics, panel, preview, sim, trace, uf2,
};

/// Project commands of idle-head: build and run the firmware in QEMU, test,
/// benchmark, and look at the loops it plays.
#[derive(Debug, Parser)]
#[command(
    name = "cargo xtask",
    bin_name = "cargo xtask",
    after_help = "qemu, test and bench install what is missing: the thumbv6m-none-eabi Rust \
                  target (rustup) and, as root on Debian/Ubuntu, the qemu-system-arm package \
                  (apt-get)."
)]
pub struct Cli {
    /// The command; without one, this help.
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// One of the project commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Build the QEMU image, run it under emulation and show the head's motion.
    ///
    /// Prints the decoded defmt log and the summary line, which it checks: no
    /// missed frame, no pulse outside a servo's limits, and the checksum of
    /// the loops equal to the host's; draws the three axes over the run into
    /// target/qemu/motion.png.
    Qemu {
        #[command(flatten)]
        bless: Bless,
        #[command(flatten)]
        timeout: Timeout,
    },
    /// Run every check: host tests, rustfmt, clippy, the Pico build, the QEMU
    /// log, the benchmark.
    ///
    /// Host tests, rustfmt, clippy (firmware and host crates), the Pico build
    /// with its memory budget, the QEMU run compared with qemu/expected.log,
    /// and the benchmark with its budget. Ends with `N passed, M failed`.
    Test {
        #[command(flatten)]
        bless: Bless,
        #[command(flatten)]
        timeout: Timeout,
        #[command(flatten)]
        budget: Budget,
    },
    /// Run the boot-time benchmark in QEMU: a table and a verdict.
    ///
    /// Instructions of the motion engine for the default set, for W = 15, 59,
    /// 239 (N = 900) and N = 450, 900, 1800 (W = 59), next to a direct-form f32
    /// smoothing, then a verdict. Fails if the default set takes more than its
    /// budget of 150,000 instructions.
    Bench {
        #[command(flatten)]
        timeout: Timeout,
        #[command(flatten)]
        budget: Budget,
    },
    /// Write the stages of a loop as CSV and PNG, with its metrics.
    ///
    /// Writes <out>/<stem>.csv (header n,walk,smoothed,normalized,final;
    /// degrees) and <out>/<stem>.png (the stages as stacked panels, the split
    /// point marked, the loop's metrics) and prints the metrics. With none of
    /// the loop options (--axis, --seed, --n, --w, --range, --closure) it
    /// previews the three default axes (paper, Table 2; N = 900) as
    /// <out>/pitch.*, roll.*, yaw.*.
    Preview(preview::Args),
    /// Loop-quality metrics of both closures over many seeds.
    ///
    /// Generates one loop per seed with each closure (seamless, paper) and
    /// prints the distributions (min, median, p99, max) of the loop metrics of
    /// the stored loop: max|d1|/P95|d1|, max|d2|/P95|d2|, liveliness, the
    /// margins to [α1, α2] and the start value; then, per closure, how many
    /// seeds break continuity ≤ 3.
    ///
    /// Seed i (i = 0..count) is i*2654435761 + 12345 (mod 2^32) and runs on
    /// axis i mod 3 (pitch, roll, yaw) with that axis' default row (paper,
    /// Table 2), so each default range gets a third of the seeds.
    Metrics(metrics::Args),
    /// Run the Pico image in the RP2040 emulator: its log, every servo pulse
    /// checked against the host.
    ///
    /// Builds the Pico image (`cargo build --release`, the image `cargo run
    /// --release` flashes) and runs it in the RP2040 emulator rp2040js under
    /// Node.js: the decoded log, a table of each servo's pulses checked
    /// against the duties the host computes frame for frame, the RP2040
    /// cycles of each frame update, the peak stack, and a last line `sim
    /// summary frames=<n> pulses=<n> mismatches=<n> period_ns=<min>..<max>
    /// first_us=<p>,<r>,<y> watchdog_resets=<n>`. Fails if a pulse differs
    /// from the host's duty by more than one PWM count, a frame is missing
    /// or extra, or the emulator stops making progress. Installs on first
    /// use: Node.js and npm (apt-get, as root) and the pinned emulator (`npm
    /// ci` in sim/).
    Sim(sim::Args),
    /// Simulate the firmware's frames on the host with scripted commands:
    /// CSV, and a PNG on request.
    ///
    /// Runs the core's frame engine (idle loops, behaviour mixer, command
    /// queue, frame driver) frame by frame as the frame task does, with the
    /// built-in configuration, and writes one CSV row per frame: the frame,
    /// its time in ms, the three commanded angles in m° after every safety
    /// stage and the three pulse widths in ns on the Pico's PWM counts. A
    /// script line is `<seconds> <command>` (`2.5 nod 6000 900`) in the
    /// console's words: a gesture (any the console's `help` lists: nod,
    /// shake, tilt, ...) [amplitude m°] [ms] [cycles=N] [intensity=PCT]; look <pitch m°> <yaw m°> [ms] [hold=MS|hold=stay];
    /// center [ms]; idle on|off; idle amp <percent>; stop. Blank lines and
    /// `#` comments are ignored; a script runs top to bottom, so a line timed
    /// before the one above it is an error, as is any bad line: each is
    /// named, and then nothing runs. The CSV (and the PNG, given `--png`
    /// alone) go to trace/ in the target directory unless told otherwise.
    Trace(trace::Args),
    /// Talk to a head: lines from stdin, replies to stdout, one per line.
    ///
    /// The bytes go through unchanged: a line that is not UTF-8 reaches the
    /// head, which answers it with an error; lines end at CR, LF or CR LF,
    /// as on the head, and a last line without a line end gets an LF. What
    /// ends a session early (a port that closes, lines left unanswered) is
    /// said on stderr, and the command fails.
    ///
    /// With --qemu the firmware runs in QEMU (a clean head at real time: no
    /// script, no injected faults) and its UART0 carries the console; when
    /// stdin closes, the firmware is stopped and its summary line printed.
    /// With --port <dev> that serial port is opened (115200 8N1); with
    /// neither, the Pico is found by its USB VID:PID 16c0:27dd.
    Console(console::Args),
    /// Serve the browser control panel, bridged to a head.
    ///
    /// Prints `panel: http://ADDR:PORT/` once the page can be loaded. With
    /// --sim the shipped Pico image runs in the RP2040 emulator at real
    /// time and the page talks to its USB serial port; with --qemu to the
    /// QEMU image's UART0; with --port <dev> to a board's serial port. The
    /// page connects to the bridge when it loads. Without a bridge the page
    /// talks to a board itself over Web Serial (Chromium, Edge, Opera).
    /// --export <dir> writes the page with its dependencies for any static
    /// host instead. Ctrl-C stops everything it started.
    Panel(panel::Args),
    /// Write the firmware as a UF2 file, for a board in BOOTSEL mode.
    ///
    /// Builds the board's release image (unless an ELF is given) and writes
    /// <ELF>.uf2 beside it: the ELF's loadable segments at their flash
    /// addresses, one 256-byte page per block, of the board's UF2 family
    /// (RP2040 0xe48bff56; RP2350 Arm Secure 0xe48bff59). The file is read
    /// back and compared with the ELF before it is kept. Copy it onto the
    /// USB drive the board shows when it is plugged in with BOOTSEL held.
    Uf2(uf2::Args),
    /// Flash an image: the runner of `cargo run --release`.
    ///
    /// Copies the image's UF2 onto the board's BOOTSEL drive if one is
    /// mounted; else runs `probe-rs run --chip <chip> <ELF>` if probe-rs is
    /// installed; else writes the UF2 and says how to flash it, or what to
    /// install.
    Flash(flash::Args),
    /// Build the book (docs/) into target/book and check every link in it.
    ///
    /// Writes the measured figures page (docs/design/figures.md, not in
    /// git) from target/figures.json, which `cargo xtask test` and `cargo
    /// xtask metrics` fill; builds the book with the pinned mdBook (installed
    /// with `cargo install` when missing); then fails if a relative link of a
    /// rendered page, or of the README, does not reach a file, or its
    /// #anchor an id in the page it points to.
    Book,
}

impl Command {
    /// The options of a command that runs QEMU.
    pub fn options(bless: Option<Bless>, timeout: Timeout, budget: Option<Budget>) -> Options {
        Options {
            bless: bless.is_some_and(|b| b.bless),
            timeout: Duration::from_secs(timeout.timeout),
            no_budget: budget.is_some_and(|b| b.no_budget),
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::{CommandFactory, error::ErrorKind};

    use super::*;

    fn parse(args: &[&str]) -> Result<Option<Command>, clap::Error> {
        Cli::try_parse_from(std::iter::once("cargo xtask").chain(args.iter().copied()))
            .map(|cli| cli.command)
    }

    /// The error of a bad command line, as printed.
    fn error(args: &[&str]) -> String {
        parse(args).unwrap_err().to_string()
    }

    #[test]
    fn the_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn defaults_as_documented() {
        assert!(parse(&[]).unwrap().is_none());
        let Some(Command::Test {
            bless,
            timeout,
            budget,
        }) = parse(&["test"]).unwrap()
        else {
            panic!("not `test`");
        };
        let options = Command::options(Some(bless), timeout, Some(budget));
        assert!(!options.bless && !options.no_budget);
        assert_eq!(options.timeout, Duration::from_secs(120));
        let Some(Command::Metrics(args)) = parse(&["metrics"]).unwrap() else {
            panic!("not `metrics`");
        };
        assert_eq!(
            (args.seeds, args.shape.n(), args.shape.w()),
            (10_000, 900, 59)
        );
        assert!(!args.shape.given());
    }

    #[test]
    fn options_parse() {
        let Some(Command::Qemu { bless, timeout }) =
            parse(&["qemu", "--bless", "--timeout", "30"]).unwrap()
        else {
            panic!("not `qemu`");
        };
        let options = Command::options(Some(bless), timeout, None);
        assert!(options.bless);
        assert_eq!(options.timeout, Duration::from_secs(30));
        let Some(Command::Bench { budget, .. }) = parse(&["bench", "--no-budget"]).unwrap() else {
            panic!("not `bench`");
        };
        assert!(budget.no_budget);
        let Some(Command::Metrics(args)) =
            parse(&["metrics", "--seeds=300", "--n", "450", "--w", "15"]).unwrap()
        else {
            panic!("not `metrics`");
        };
        assert_eq!((args.seeds, args.shape.n(), args.shape.w()), (300, 450, 15));
    }

    #[test]
    fn the_trace_writes_under_the_target_directory_unless_told() {
        let trace = |args: &[&str]| {
            let args: Vec<&str> = ["trace", "--seconds", "2"]
                .into_iter()
                .chain(args.iter().copied())
                .collect();
            match parse(&args).unwrap() {
                Some(Command::Trace(args)) => (args.out, args.png),
                other => panic!("not `trace`: {other:?}"),
            }
        };
        assert_eq!(trace(&[]), (None, None));
        assert_eq!(trace(&["--png"]), (None, Some(None)));
        assert_eq!(
            trace(&["--png", "a.png", "--out", "a.csv"]),
            (Some("a.csv".into()), Some(Some("a.png".into())))
        );
    }

    #[test]
    fn a_bad_option_is_named() {
        assert!(error(&["qemu", "--frobnicate"]).contains("--frobnicate"));
        assert!(error(&["qemu", "--timeout", "0"]).contains("--timeout"));
        assert!(error(&["test", "--timeout", "soon"]).contains("--timeout"));
        // Each command takes only the options that mean something to it.
        assert!(error(&["bench", "--bless"]).contains("--bless"));
        assert!(error(&["qemu", "--no-budget"]).contains("--no-budget"));
        assert!(error(&["metrics", "--seeds", "0"]).contains("--seeds"));
        assert!(error(&["metrics", "--n", "-3"]).contains("--n"));
        assert!(error(&["qemu", "--timeout", "-5"]).contains("--timeout"));
        assert!(error(&["preview", "--bogus"]).contains("--bogus"));
        assert!(error(&["deploy"]).contains("deploy"));
        assert!(error(&["flash"]).contains("<ELF>"));
        assert!(error(&["uf2", "--board", "pico3"]).contains("pico3"));
    }

    #[test]
    fn help_works_everywhere() {
        for command in [
            &[][..],
            &["qemu"],
            &["test"],
            &["bench"],
            &["preview"],
            &["metrics"],
        ] {
            for flag in ["-h", "--help"] {
                let args: Vec<&str> = command.iter().copied().chain([flag]).collect();
                let kind = parse(&args).unwrap_err().kind();
                assert_eq!(kind, ErrorKind::DisplayHelp, "{args:?}");
            }
        }
        let help = error(&["help", "preview"]);
        assert!(help.contains("--range <A1> <A2>"), "{help}");
    }
}
