//! Host-side project commands, run as `cargo xtask <command>` from anywhere in
//! the repository (the alias in `.cargo/config.toml` builds this crate for the
//! host).
//!
//! - `cargo xtask qemu`: build the QEMU image, run it and show the head's motion.
//! - `cargo xtask test`: every check the project has (host tests, formatting,
//!   lints, the Pico build and its memory budget, the QEMU log snapshot, the
//!   boot-time benchmark and its budget).
//! - `cargo xtask bench`: the boot-time benchmark in QEMU (engine against a
//!   direct-form f32 smoothing), as a table with a verdict.
//! - `cargo xtask preview`: CSV and PNG of a loop's stages (walk, smoothing,
//!   normalisation, closure), for people.
//! - `cargo xtask metrics`: loop-quality metrics over many seeds, both closures.
//!
//! The firmware commands install what they need and is missing: the
//! firmware's Rust target and, when running as root on Debian or Ubuntu, QEMU.
//! `preview` and `metrics` run the core library on the host only.

mod args;
mod bench;
mod elf;
mod metrics;
mod preview;
mod project;
mod qemu;
mod reference;
mod render;
mod setup;
mod snapshot;
mod test;

use std::{process::ExitCode, time::Duration};

use anyhow::{Context, Result, bail};

const HELP: &str = "\
Usage: cargo xtask <command> [options]

Commands:
  qemu     Build the QEMU image, run it under emulation and show the head's
           motion: the decoded defmt log, the summary line and a plot of the
           three axes over the run.
  test     Run every check: host tests, rustfmt, clippy (firmware and host
           crates), the Pico build with its memory budget, the QEMU run
           compared with qemu/expected.log, and the benchmark with its
           budget. Ends with `N passed, M failed`.
  bench    Build the QEMU benchmark image and run it: instructions of the
           motion engine for the default set, for W = 15, 59, 239 (N = 900)
           and N = 450, 900, 1800 (W = 59), next to a direct-form f32
           smoothing, then a verdict. Fails if the default set takes more
           than its budget of 150,000 instructions.
  preview  Write the stages of a loop as CSV and PNG (walk, smoothed,
           normalised, final loop with the split point) with its metrics;
           with no options, the three default axes. Options: `preview -h`.
  metrics  Loop-quality metrics (continuity, liveliness, range, start) of
           both closures over many seeds. Options: `metrics -h`.
  help     Show this text.

Options (qemu, test, bench):
  --bless          Re-record qemu/expected.log from this run (the run itself
                   must succeed; qemu and test).
  --timeout <s>    Stop QEMU after this many seconds of wall time
                   (default 120); a run that times out fails.
  --no-budget      Report the benchmark's instruction budget without failing
                   on it (bench and test).
  -h, --help       Show this text.

qemu, test and bench install what is missing: the thumbv6m-none-eabi Rust
target (rustup) and, as root on Debian/Ubuntu, the qemu-system-arm package
(apt-get).
";

/// Options shared by the commands.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Re-record the expected QEMU log instead of comparing against it.
    pub bless: bool,
    /// Wall-clock limit for one QEMU run.
    pub timeout: Duration,
    /// Report the benchmark's instruction budget without failing on it.
    pub no_budget: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            bless: false,
            // A hung firmware must fail CI, not stall it; the QEMU run takes
            // well under a minute.
            timeout: Duration::from_secs(120),
            no_budget: false,
        }
    }
}

enum Command {
    Qemu(Options),
    Test(Options),
    Bench(Options),
    Preview(preview::Args),
    Metrics(metrics::Args),
    Help,
    /// A command's own help text.
    Usage(&'static str),
}

fn parse_args(mut args: impl Iterator<Item = String>) -> Result<Command> {
    let Some(command) = args.next() else {
        return Ok(Command::Help);
    };
    // Commands with options of their own.
    match command.as_str() {
        "preview" => {
            let args = preview::Args::parse(args)?;
            return Ok(args.map_or(Command::Usage(preview::HELP), Command::Preview));
        }
        "metrics" => {
            let args = metrics::Args::parse(args)?;
            return Ok(args.map_or(Command::Usage(metrics::HELP), Command::Metrics));
        }
        _ => {}
    }
    let mut options = Options::default();
    let mut help = false;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--bless" => options.bless = true,
            "--no-budget" => options.no_budget = true,
            "--timeout" => {
                let value = args
                    .next()
                    .context("`--timeout` needs a number of seconds")?;
                options.timeout = parse_seconds(&value)?;
            }
            "-h" | "--help" => help = true,
            other => {
                if let Some(value) = other.strip_prefix("--timeout=") {
                    options.timeout = parse_seconds(value)?;
                } else {
                    bail!("unknown option `{other}` (see `cargo xtask help`)");
                }
            }
        }
    }
    if help {
        return Ok(Command::Help);
    }
    Ok(match command.as_str() {
        "qemu" => Command::Qemu(options),
        "test" => Command::Test(options),
        "bench" => Command::Bench(options),
        "help" | "-h" | "--help" => Command::Help,
        other => bail!("unknown command `{other}` (see `cargo xtask help`)"),
    })
}

fn parse_seconds(value: &str) -> Result<Duration> {
    let seconds: u64 = value
        .parse()
        .with_context(|| format!("`--timeout {value}`: expected whole seconds"))?;
    if seconds == 0 {
        bail!("`--timeout` must be at least 1 second");
    }
    Ok(Duration::from_secs(seconds))
}

fn main() -> ExitCode {
    let result = parse_args(std::env::args().skip(1)).and_then(|command| match command {
        Command::Help => {
            print!("{HELP}");
            Ok(true)
        }
        Command::Usage(text) => {
            print!("{text}");
            Ok(true)
        }
        Command::Qemu(options) => qemu::command(options),
        Command::Test(options) => test::command(options),
        Command::Bench(options) => bench::command(options),
        Command::Preview(args) => preview::command(&args),
        Command::Metrics(args) => metrics::command(&args),
    });
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}
