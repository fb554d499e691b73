//! The servos' PWM rate (`servo rate <hz>`): how often a servo gets its
//! pulse, and so how often the frames come; and the output side of a
//! change of it, [`SetPeriod`].
//!
//! Analog servos want 50 Hz: their amplifier drives the motor for a
//! stretch after each pulse, and pulses much closer together heat it (or
//! make it hum and jitter). Digital servos often take pulses up to 300 Hz
//! or more and answer faster. The servo's data sheet decides.

use embedded_hal::pwm::SetDutyCycle;

use crate::units::Microseconds;

/// The PWM rate of the three servos, whole Hz in
/// [`MIN`](Self::MIN)`..=`[`MAX`](Self::MAX); the frame rate follows it.
///
/// The period is a whole number of µs (the frame clock's unit), the
/// nearest to `10⁶/hz`: 50 Hz is 20 000 µs exactly, 333 Hz 3003 µs
/// (333.0003 Hz), 60 Hz 16 667 µs (59.9988 Hz).
///
/// ```
/// use idle_head_core::servo::ServoRate;
/// use idle_head_core::Microseconds;
/// assert_eq!(ServoRate::DEFAULT.hz(), 50);
/// assert_eq!(ServoRate::new(333).unwrap().period(), Microseconds(3003));
/// assert_eq!(ServoRate::new(200).unwrap().period(), Microseconds(5000));
/// assert_eq!(ServoRate::new(334), None);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoRate(u16);

impl ServoRate {
    /// The slowest rate: 50 Hz, what every hobby servo takes.
    pub const MIN: Self = Self(50);
    /// The fastest rate: 333 Hz (a 3003 µs period: the longest pulse any
    /// calibration allows, 2500 µs, still ends a tenth of a period before
    /// the next frame's write).
    pub const MAX: Self = Self(333);
    /// 50 Hz.
    pub const DEFAULT: Self = Self::MIN;

    /// `hz` Hz, if within [`MIN`](Self::MIN)`..=`[`MAX`](Self::MAX).
    #[must_use]
    pub const fn new(hz: u16) -> Option<Self> {
        if hz < Self::MIN.0 || hz > Self::MAX.0 {
            None
        } else {
            Some(Self(hz))
        }
    }

    /// The rate in Hz, as set.
    #[must_use]
    pub const fn hz(self) -> u16 {
        self.0
    }

    /// The PWM and frame period: `10⁶/hz` µs, rounded to the nearest µs.
    #[must_use]
    pub const fn period(self) -> Microseconds {
        // (Never 0: the constructor sees to it; the frame path must not
        // divide by what it cannot see.)
        let hz = if self.0 == 0 { 1 } else { self.0 as u32 };
        Microseconds((1_000_000 + hz / 2) / hz)
    }
}

impl Default for ServoRate {
    fn default() -> Self {
        Self::DEFAULT
    }
}

// Every period of the range leaves the longest pulse a tenth of a period
// before the next write (the PWM outputs' phase rule).
const _: () = {
    let p = ServoRate::MAX.period().0;
    assert!(super::bounds::MAX_PULSE.0 <= p - p / 10);
    assert!(ServoRate::MIN.period().0 == 20_000);
};

/// A servo output whose PWM period can change while it runs.
///
/// The frame driver sets it between two frames
/// ([`FrameDriver::set_pwm_period`](crate::driver::FrameDriver::set_pwm_period)),
/// before the last frame at the old period is written; from then on
/// [`max_duty_cycle`](SetDutyCycle::max_duty_cycle) counts the new period.
/// An output with the phase rule of the RP boards (each write a tenth of a
/// period before the wrap that latches it) restarts its period at that
/// next write, the write a tenth of the new period before its first wrap:
/// no pulse is cut or stretched, and the old period's last pulse is the
/// last one at the old rate.
pub trait SetPeriod: SetDutyCycle {
    /// How late after its deadline a frame's duty may still be written for
    /// its own pulse, as a divisor of the period: the RP boards' outputs
    /// latch a duty a tenth of a period after the deadline
    /// ([`WRAP_MARGIN_DIVISOR`](crate::pwm_clock::WRAP_MARGIN_DIVISOR)); an
    /// output with no such latch (a simulated one) takes a duty any time
    /// in the period (1, the default).
    const LATCH_DIVISOR: u32 = 1;

    /// Runs the output at `period` from the next duty written on.
    ///
    /// # Errors
    /// The output cannot make `period` exactly; it keeps the period it had.
    fn set_period(&mut self, period: Microseconds) -> Result<(), Self::Error>;
}
