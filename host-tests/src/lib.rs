//! Shared helpers for the host tests of the `idle-head` core.

pub mod behaviour;
pub mod console;
pub mod rig;
pub mod tracked;

use embedded_hal_mock::eh1::MockError;
use embedded_hal_mock::eh1::pwm::{Mock, Transaction};
use idle_head_core::Angle;
use idle_head_core::driver::{DriverConfig, DriverParams};

/// Cases for a property test: `default`, or `PROPTEST_CASES` when set, for
/// a longer soak (`PROPTEST_CASES=20000 cargo test --release driver::`;
/// a case count written in a test's config would otherwise override
/// proptest's own variable). A value that is not a number is reported.
#[must_use]
pub fn cases(default: u32) -> u32 {
    env_number("PROPTEST_CASES").unwrap_or(default)
}

/// The number in the environment variable `name`, if it is set; a value
/// that is not a number is a mistake to report (a panic naming it), not
/// to run CI's cases under.
#[must_use]
pub fn env_number<T: std::str::FromStr>(name: &str) -> Option<T> {
    let text = std::env::var(name).ok()?;
    match text.parse() {
        Ok(n) => Some(n),
        Err(_) => panic!(
            "{name}={text:?}: not a number of {}",
            std::any::type_name::<T>()
        ),
    }
}

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
    /// Every period set ([`SetPeriod`](idle_head_core::servo::SetPeriod)),
    /// with the number of writes before it.
    pub periods: Vec<(usize, u32)>,
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

/// A recorder counts 1 µs a tick at any period (the rig's channels).
impl idle_head_core::servo::SetPeriod for Recorder {
    fn set_period(&mut self, period: idle_head_core::Microseconds) -> Result<(), Broken> {
        self.max_duty = u16::try_from(period.0).map_err(|_| Broken)?;
        self.periods.push((self.written.len(), period.0));
        Ok(())
    }
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
    use idle_head_core::Millis;
    use idle_head_core::driver::{DegreesPerSecond, DegreesPerSecondSquared, MotionLimits};
    let mut cfg = DriverConfig::DEFAULT;
    cfg.fade = Millis(0);
    cfg.motion = [MotionLimits {
        max_speed: DegreesPerSecond(100_000),
        max_accel: DegreesPerSecondSquared(100_000_000),
    }; 3];
    cfg
}

/// Proptest strategies for configurations, shared by the test files.
pub mod strategies {
    use std::ops::RangeInclusive;

    use idle_head_core::driver::{
        DegreesPerSecond, DegreesPerSecondSquared, DriverConfig, MotionLimits,
    };
    use idle_head_core::servo::{Direction, NanosPerDegree, ServoCalibration};
    use idle_head_core::{Angle, AngleRange, Microseconds, Millis};
    use proptest::prelude::*;

    /// A valid calibration with limits within `±limit` m° and `per_degree`
    /// ns/°: random neutral, scale, direction and limits, with pulse limits
    /// just wide enough (plus a random margin) to reach the limits, inside
    /// the hard pulse bounds.
    pub fn calibration_in(
        limit: i32,
        per_degree: RangeInclusive<u32>,
    ) -> impl Strategy<Value = ServoCalibration> {
        (
            1200u32..=1800,
            per_degree,
            any::<bool>(),
            -limit..=0,
            0..=limit,
            0u32..200,
            0u32..200,
        )
            .prop_map(|(neutral, per_degree, reversed, lo, hi, below, above)| {
                // The limits' pulses, margins included, stay inside the
                // hard bounds (500..=2500 µs): at most 700 µs below the
                // neutral pulse and 2300 µs above, less the margin.
                let room = |us: u32| i64::from(us) * 1_000_000 / i64::from(per_degree.max(1));
                let (down, up) = (room(neutral - 700), room(2300 - neutral));
                let (down, up) = if reversed { (up, down) } else { (down, up) };
                let lo = i64::from(lo).max(-down) as i32;
                let hi = i64::from(hi).min(up) as i32;
                let mut cal = ServoCalibration {
                    neutral: Microseconds(neutral),
                    per_degree: NanosPerDegree(per_degree),
                    direction: if reversed {
                        Direction::Reversed
                    } else {
                        Direction::Normal
                    },
                    min_pulse: Microseconds(0),
                    max_pulse: Microseconds(u32::MAX),
                    limits: AngleRange {
                        min: Angle::from_millidegrees(lo),
                        max: Angle::from_millidegrees(hi),
                    },
                };
                let ends = [
                    cal.raw_pulse_us(cal.limits.min),
                    cal.raw_pulse_us(cal.limits.max),
                ];
                let (p_lo, p_hi) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
                cal.min_pulse = Microseconds((p_lo as u32).min(neutral - 1).saturating_sub(below));
                cal.max_pulse = Microseconds((p_hi as u32).max(neutral + 1) + above);
                cal
            })
    }

    /// A valid calibration of a hobby servo's scale, limits within ±40°.
    pub fn calibration() -> impl Strategy<Value = ServoCalibration> {
        calibration_in(40_000, 5000..=20_000)
    }

    /// Speed and acceleration limits from a crawl to far beyond any servo.
    pub fn limits() -> impl Strategy<Value = MotionLimits> {
        (1u32..=400, 1u32..=20_000).prop_map(|(v, a)| MotionLimits {
            max_speed: DegreesPerSecond(v),
            max_accel: DegreesPerSecondSquared(a),
        })
    }

    prop_compose! {
        /// A valid driver configuration: random calibrations, limits, neutral
        /// pose, fade, fault policy and frame period.
        pub fn config()(
            servos in [calibration(), calibration(), calibration()],
            motion in [limits(), limits(), limits()],
            pose in [0.0f64..=1.0, 0.0f64..=1.0, 0.0f64..=1.0],
            fade in 0u32..3000,
            disable_after in 1u32..600,
            frame_us in prop_oneof![Just(20_000u32), Just(10_000), Just(3_000)],
        ) -> DriverConfig {
            let mut cfg = DriverConfig::DEFAULT;
            cfg.frame_period = Microseconds(frame_us);
            cfg.servos = servos;
            cfg.motion = motion;
            for i in 0..3 {
                let l = servos[i].limits;
                let (lo, hi) = (f64::from(l.min.millidegrees()), f64::from(l.max.millidegrees()));
                cfg.neutral_pose[i] = Angle::from_millidegrees((lo + pose[i] * (hi - lo)).round() as i32);
            }
            cfg.fade = Millis(fade);
            cfg.faults.disable_after = Millis(disable_after);
            cfg
        }
    }
}
