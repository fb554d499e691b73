//! The command line: every command and its options (clap). The option groups
//! that several commands share are in `args.rs`.

use clap::{Parser, Subcommand};

use crate::{args::Timeout, console, flash, panel, preview, sim, trace, uf2};

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
        /// are counted as left out), e.g. `--only emulator`.
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
            (&["sim", "--drill", "--store"], "--store"),
            (&["trace", "--seconds", "1", "--rate", "0"], "--rate"),
            (&["flash"], "<ELF>"),
            (&["deploy"], "deploy"),
        ] {
            assert!(parse(args).unwrap_err().contains(named), "{args:?}");
        }
    }

    // `docs/dev/xtask.md` against the definition: every command has its
    // line in the page, every long option a line that names its command.

    /// Whether `line` names `word`, not a longer command or option.
    fn names(line: &str, word: &str) -> bool {
        line.match_indices(word).any(|(at, _)| {
            let next = line[at + word.len()..].chars().next();
            !next.is_some_and(|c| c.is_ascii_alphanumeric() || c == '-')
        })
    }

    /// What the page misses of the definition: commands, then options.
    fn missing(page: &str) -> Vec<String> {
        let mut missing = Vec::new();
        for command in Cli::command().get_subcommands() {
            let name = command.get_name();
            let named = format!("cargo xtask {name}");
            let lines: Vec<&str> = page.lines().filter(|l| names(l, &named)).collect();
            if lines.is_empty() {
                missing.push(format!("`cargo xtask {name}`"));
                continue;
            }
            for arg in command.get_arguments() {
                let Some(long) = arg.get_long() else { continue };
                if arg.is_hide_set() || long == "help" {
                    continue;
                }
                let option = format!("--{long}");
                if !lines.iter().any(|line| names(line, &option)) {
                    missing.push(format!("`cargo xtask {name} {option}`"));
                }
            }
        }
        missing
    }

    #[test]
    fn the_page_names_every_command_and_option() {
        let path = crate::project::root().join("docs/dev/xtask.md");
        let page = std::fs::read_to_string(&path).expect("docs/dev/xtask.md");
        let missing = missing(&page);
        assert!(
            missing.is_empty(),
            "docs/dev/xtask.md does not name {} (on a line with its command)",
            missing.join(", ")
        );
    }

    #[test]
    fn a_command_or_option_left_out_is_named() {
        let page = "| `cargo xtask qemu --bless --timeout S` | |\n| `cargo xtask testing` |\n";
        let left_out = missing(page);
        assert!(!left_out.iter().any(|m| m.contains("qemu")), "{left_out:?}");
        assert!(left_out.contains(&"`cargo xtask test`".to_owned()));
        // An option named on another command's line does not count.
        let page = "`cargo xtask bench`\n`cargo xtask test --no-budget`\n";
        let left_out = missing(page);
        assert!(left_out.contains(&"`cargo xtask bench --no-budget`".to_owned()));
        assert!(!left_out.contains(&"`cargo xtask test --no-budget`".to_owned()));
    }
}
