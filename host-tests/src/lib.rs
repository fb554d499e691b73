//! Shared helpers for the host tests of the `idle-head` core.

use embedded_hal_mock::eh1::MockError;
use embedded_hal_mock::eh1::pwm::{Mock, Transaction};
use idle_head::Angle;
use idle_head::driver::{DriverConfig, DriverParams};

/// Validated parameters of `cfg` (panics with the error if invalid: tests only).
#[must_use]
pub fn params(cfg: &DriverConfig) -> DriverParams {
    cfg.build()
        .unwrap_or_else(|e| panic!("{e:?}: {}", e.message()))
}

/// A PWM mock expecting `max_duty_cycle` (returning `max_duty`) then `tail`.
#[must_use]
pub fn pwm(max_duty: u16, tail: &[Transaction]) -> Mock {
    let mut t = vec![Transaction::max_duty_cycle(max_duty)];
    t.extend_from_slice(tail);
    Mock::new(&t)
}

/// Expected successful writes of `duties`.
#[must_use]
pub fn writes(duties: &[u16]) -> Vec<Transaction> {
    duties
        .iter()
        .map(|&d| Transaction::set_duty_cycle(d))
        .collect()
}

/// An expected write of `duty` that fails.
#[must_use]
pub fn failing(duty: u16) -> Transaction {
    Transaction::set_duty_cycle(duty).with_error(io_error())
}

/// The error injected into failing writes.
#[must_use]
pub fn io_error() -> MockError {
    MockError::Io(std::io::ErrorKind::NotConnected)
}

/// Angles from millidegrees.
#[must_use]
pub fn mdeg<const N: usize>(v: [i32; N]) -> [Angle; N] {
    v.map(Angle::from_millidegrees)
}

/// A PWM channel that records every duty written, with injectable failures
/// (for long runs where listing every expected transaction is impractical).
#[derive(Debug, Default)]
pub struct Recorder {
    /// Ticks per PWM period reported by `max_duty_cycle`.
    pub max_duty: u16,
    /// Every duty passed to `set_duty_cycle`, failed ones included.
    pub written: Vec<u16>,
    /// Fail this many of the next writes.
    pub fail_next: u32,
    /// Then fail write `n` (counting all writes) if `fail_pattern[n % len]`.
    pub fail_pattern: Vec<bool>,
}

impl Recorder {
    /// A channel with `max_duty` ticks per period.
    #[must_use]
    pub fn new(max_duty: u16) -> Self {
        Self {
            max_duty,
            ..Self::default()
        }
    }
}

/// The error of a failing [`Recorder`] write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Broken;

impl embedded_hal::pwm::Error for Broken {
    fn kind(&self) -> embedded_hal::pwm::ErrorKind {
        embedded_hal::pwm::ErrorKind::Other
    }
}

impl embedded_hal::pwm::ErrorType for Recorder {
    type Error = Broken;
}

impl embedded_hal::pwm::SetDutyCycle for Recorder {
    fn max_duty_cycle(&self) -> u16 {
        self.max_duty
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Broken> {
        self.written.push(duty);
        if self.fail_next > 0 {
            self.fail_next -= 1;
            return Err(Broken);
        }
        let n = self.written.len() - 1;
        match self.fail_pattern.get(n % self.fail_pattern.len().max(1)) {
            Some(true) => Err(Broken),
            _ => Ok(()),
        }
    }
}

/// The default configuration with 1 duty tick per µs (20 000 ticks per 20 ms),
/// no fade and motion limits far above anything the tests command, so that the
/// commanded angle is exactly neutral pose + offset.
#[must_use]
pub fn direct_config() -> DriverConfig {
    use idle_head::Millis;
    use idle_head::driver::{DegreesPerSecond, DegreesPerSecondSquared, MotionLimits};
    let mut cfg = DriverConfig::DEFAULT;
    cfg.fade = Millis(0);
    cfg.motion = [MotionLimits {
        max_speed: DegreesPerSecond(100_000),
        max_accel: DegreesPerSecondSquared(100_000_000),
    }; 3];
    cfg
}
