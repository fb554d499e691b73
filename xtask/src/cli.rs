//! The command line: every command and its options (clap). The option groups
//! that several commands share are in `args.rs`.

use clap::{Parser, Subcommand};

use crate::{args::Timeout, console, flash, metrics, panel, preview, sim, trace, uf2};

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
        /// Re-record boards/qemu/expected.log from this run (the run itself must succeed).
        #[arg(long)]
        bless: bool,
        #[command(flatten)]
        timeout: Timeout,
    },
    /// Run every check: host tests, rustfmt, clippy, the images and their
    /// budgets, QEMU and its expected log, the emulator, the benchmark, the
    /// panel in a browser, the book. Ends with `N passed, M failed`.
    Test {
        /// Re-record boards/qemu/expected.log from this run (the run itself must succeed).
        #[arg(long)]
        bless: bool,
        #[command(flatten)]
        timeout: Timeout,
        /// Report the benchmark's instruction budget without failing on it.
        #[arg(long)]
        no_budget: bool,
        /// Run only the stages whose name contains this text (the others
        /// are listed as skipped), e.g. `--only emulator`.
        #[arg(long, value_name = "TEXT")]
        only: Option<String>,
        /// One emulator stage, exactly this name, on images already built:
        /// how the full run starts its emulator stages side by side.
        #[arg(long, hide = true, conflicts_with = "only")]
        stage: Option<String>,
    },
    /// Run the benchmark in QEMU (boot precompute and frame update against
    /// their budgets), the tracking figures in the host trace, then the
    /// latency rows in the RP2040 emulator.
    Bench {
        #[command(flatten)]
        timeout: Timeout,
        /// Report the benchmark's instruction budget without failing on it.
        #[arg(long)]
        no_budget: bool,
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

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    use super::*;

    fn parse(args: &[&str]) -> Result<Option<Command>, String> {
        let args = std::iter::once("cargo xtask").chain(args.iter().copied());
        Cli::try_parse_from(args)
            .map(|cli| cli.command)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn the_definition_is_consistent_and_a_bad_option_is_named() {
        Cli::command().debug_assert();
        assert!(parse(&[]).unwrap().is_none());
        assert!(matches!(parse(&["test"]), Ok(Some(Command::Test { .. }))));
        // Each command takes only the options that mean something to it.
        for (args, named) in [
            (&["qemu", "--timeout", "0"][..], "--timeout"),
            (&["bench", "--bless"], "--bless"),
            (&["qemu", "--no-budget"], "--no-budget"),
            (&["metrics", "--seeds", "0"], "--seeds"),
            (&["sim", "--drill", "--store"], "--store"),
            (&["flash"], "<ELF>"),
            (&["deploy"], "deploy"),
        ] {
            assert!(parse(args).unwrap_err().contains(named), "{args:?}");
        }
    }
}
