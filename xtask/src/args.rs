//! Options that several commands share, and what the commands that run QEMU
//! take from them.

use std::time::Duration;

use clap::Args;
use idle_head_core::motion::DEFAULT_N;
use idle_head_core::servo::ServoRate;

/// Options of the commands that run QEMU (`--bless`, `--timeout`,
/// `--no-budget`).
#[derive(Debug, Clone, Copy)]
pub struct Options {
    pub bless: bool,
    pub timeout: Duration,
    pub no_budget: bool,
}

/// `--timeout` (qemu, test, bench).
#[derive(Debug, Clone, Copy, Args)]
pub struct Timeout {
    /// Stop QEMU after this many seconds of wall time; a run that times out
    /// fails.
    // A hung firmware must fail, not stall; a run takes seconds.
    #[arg(long, value_name = "s", allow_negative_numbers = true, default_value_t = 120,
          value_parser = at_least_one::<u64>)]
    pub timeout: u64,
}

pub fn at_least_one<T: std::str::FromStr + From<u8> + PartialOrd>(text: &str) -> Result<T, String> {
    match text.parse() {
        Ok(value) if value >= T::from(1) => Ok(value),
        _ => Err("expected a whole number, at least 1".to_owned()),
    }
}

/// `--rate` (trace, sim): a servo rate in Hz, as the firmware takes it.
pub fn servo_rate(text: &str) -> Result<ServoRate, String> {
    let (min, max) = (ServoRate::MIN.hz(), ServoRate::MAX.hz());
    let hz = text.parse().ok().and_then(ServoRate::new);
    hz.ok_or_else(|| format!("expected a servo rate, {min} to {max} Hz"))
}

/// `--n` and `--w` of `cargo xtask preview`.
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
    pub fn n(&self) -> usize {
        self.n.unwrap_or(DEFAULT_N)
    }
}
