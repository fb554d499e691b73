//! Options that several commands share, and what the commands that run QEMU
//! take from them.

use std::time::Duration;

use clap::Args;
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N};

/// Options of the commands that run QEMU.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Re-record the expected QEMU log instead of comparing against it.
    pub bless: bool,
    /// Wall-clock limit for one QEMU run.
    pub timeout: Duration,
    /// Report the benchmark's instruction budget without failing on it.
    pub no_budget: bool,
}

/// The window (W) of the default rows (paper, Table 2), the same for the three axes.
pub const DEFAULT_WINDOW: u16 = DEFAULT_HEAD.yaw.window;
const _: () = assert!(
    DEFAULT_HEAD.pitch.window == DEFAULT_WINDOW && DEFAULT_HEAD.roll.window == DEFAULT_WINDOW
);

/// `--bless` (qemu, test).
#[derive(Debug, Clone, Copy, Args)]
pub struct Bless {
    /// Re-record qemu/expected.log from this run (the run itself must succeed).
    #[arg(long)]
    pub bless: bool,
}

/// `--timeout` (qemu, test, bench).
#[derive(Debug, Clone, Copy, Args)]
pub struct Timeout {
    /// Stop QEMU after this many seconds of wall time; a run that times out
    /// fails.
    // A hung firmware must fail, not stall; a run takes seconds.
    #[arg(
        long,
        value_name = "s",
        allow_negative_numbers = true,
        default_value_t = 120,
        value_parser = at_least_one::<u64>
    )]
    pub timeout: u64,
}

/// A whole number, at least 1.
pub fn at_least_one<T: std::str::FromStr + From<u8> + PartialOrd>(text: &str) -> Result<T, String> {
    match text.parse() {
        Ok(value) if value >= T::from(1) => Ok(value),
        _ => Err("expected a whole number, at least 1".to_owned()),
    }
}

/// `--no-budget` (bench, test).
#[derive(Debug, Clone, Copy, Args)]
pub struct Budget {
    /// Report the benchmark's instruction budget without failing on it.
    #[arg(long)]
    pub no_budget: bool,
}

/// `--n` and `--w` (preview, metrics).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Args)]
pub struct LoopShape {
    /// Samples per loop [default: 900].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub n: Option<usize>,
    /// Hann window taps [default: 59, the default rows'].
    #[arg(long, value_name = "W", allow_negative_numbers = true)]
    pub w: Option<u16>,
}

impl LoopShape {
    /// Whether either option is given.
    pub fn given(&self) -> bool {
        self.n.is_some() || self.w.is_some()
    }

    /// Samples per loop.
    pub fn n(&self) -> usize {
        self.n.unwrap_or(DEFAULT_N)
    }

    /// Hann window taps.
    pub fn w(&self) -> u16 {
        self.w.unwrap_or(DEFAULT_WINDOW)
    }
}
