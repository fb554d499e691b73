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

/// One of the project commands (docs/dev/xtask.md tells each in full).
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Build the QEMU image, run it under emulation and show the head's motion.
    ///
    /// Prints the decoded defmt log and checks the summary line: no missed
    /// frame, no pulse outside a servo's limits, the loops' checksum the
    /// host's. Draws the three axes into target/qemu/motion.png.
    Qemu {
        #[command(flatten)]
        bless: Bless,
        #[command(flatten)]
        timeout: Timeout,
    },
    /// Run every check: host tests, rustfmt, clippy, the images and their
    /// budgets, QEMU and its expected log, the emulator, the benchmark, the
    /// panel in a browser, the book. Ends with `N passed, M failed`.
    Test {
        #[command(flatten)]
        bless: Bless,
        #[command(flatten)]
        timeout: Timeout,
        #[command(flatten)]
        budget: Budget,
        /// Run only the stages whose name contains this text (the others
        /// are listed as skipped), e.g. `--only emulator`.
        #[arg(long, value_name = "TEXT")]
        only: Option<String>,
    },
    /// Run the benchmark in QEMU (boot precompute and frame update against
    /// their budgets), the tracking figures in the host trace, then the
    /// latency rows in the RP2040 emulator.
    Bench {
        #[command(flatten)]
        timeout: Timeout,
        #[command(flatten)]
        budget: Budget,
    },
    /// Write the stages of a loop as CSV and PNG, with its metrics.
    ///
    /// Writes <out>/<stem>.csv (n,walk,smoothed,normalized,final; degrees)
    /// and <out>/<stem>.png. Without loop options (--axis, --seed, --n, --w,
    /// --range, --closure) the three default axes, as pitch.*, roll.*, yaw.*.
    Preview(preview::Args),
    /// Loop-quality metrics of both closures over many seeds.
    ///
    /// Seed i is i*2654435761 + 12345 (mod 2^32) on axis i mod 3 with that
    /// axis' default row; prints the distributions (min, median, p99, max)
    /// of the loop metrics and how many seeds break continuity ≤ 3.
    Metrics(metrics::Args),
    /// Run the Pico image in the RP2040 emulator: its log, every servo pulse
    /// checked against the host.
    ///
    /// Builds the image `cargo run --release` flashes and runs it in
    /// rp2040js under Node.js (installed on first use); fails if a pulse
    /// differs from the host's duty by more than one PWM count, a frame is
    /// missing or extra, or the emulator stops making progress.
    Sim(sim::Args),
    /// Simulate the firmware's frames on the host with scripted commands:
    /// CSV, and a PNG on request.
    ///
    /// A script line is `<seconds> <command>` in the console's words (`2.5
    /// nod 6000 900`), or `<seconds> pin <n> high|low`; a bad line is named
    /// and then nothing runs. The CSV (and the PNG, given `--png` alone)
    /// go to trace/ in the target directory unless told otherwise.
    Trace(trace::Args),
    /// Talk to a head: lines from stdin, replies to stdout, one per line.
    ///
    /// With --qemu the firmware runs in QEMU; with --port <dev> that serial
    /// port is opened (115200 8N1); with neither, the Pico is found by its
    /// USB VID:PID 16c0:27dd. What ends a session early is said on stderr.
    Console(console::Args),
    /// Serve the browser control panel, bridged to a head.
    ///
    /// --sim, --qemu or --port <dev> bridge the page to a head; without a
    /// bridge the page uses Web Serial. --export <dir> writes the page for
    /// any static host instead. Ctrl-C stops everything it started.
    Panel(panel::Args),
    /// Write the firmware as a UF2 file, for a board in BOOTSEL mode.
    ///
    /// Builds the board's release image (unless an ELF is given) and writes
    /// <ELF>.uf2 beside it.
    Uf2(uf2::Args),
    /// Flash an image: the runner of `cargo run --release`.
    ///
    /// Copies its UF2 onto the board's BOOTSEL drive if one is mounted;
    /// else runs `probe-rs run` if it is installed; else says what to do.
    Flash(flash::Args),
    /// Build the book (docs/) into target/book and check every link in it.
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
    use clap::CommandFactory;

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
            ..
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
        assert_eq!(
            (options.bless, options.timeout),
            (true, Duration::from_secs(30))
        );
        let Some(Command::Bench { budget, .. }) = parse(&["bench", "--no-budget"]).unwrap() else {
            panic!("not `bench`");
        };
        assert!(budget.no_budget);
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
}
