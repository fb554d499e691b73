//! Virtual servo PWM channels: they record every duty written and check it
//! against their servo's pulse limits, independently of the frame driver's
//! own clamping; one can be told to fail its writes (fault injection). A
//! new period (`servo rate`) is counted as the Pico's slice counts it
//! ([`SliceClock::for_period`] at its 125 MHz).

use embedded_hal::pwm::{Error, ErrorKind, ErrorType, SetDutyCycle};
use idle_head_core::Microseconds;
use idle_head_core::pwm_clock::{PICO_SYS_HZ, SliceClock};
use idle_head_core::servo::{ServoCalibration, SetPeriod, bounds};

/// Why a virtual channel rejected a write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum VirtualPwmError {
    /// A fault injected by the test schedule.
    Injected,
    /// The duty was above the channel's maximum (as embassy-rp rejects it).
    AboveMax,
    /// No clock of the Pico's slice makes the period.
    Period,
}

impl Error for VirtualPwmError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

/// What a virtual channel saw.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, defmt::Format)]
pub struct ChannelLog {
    /// Writes accepted (the output changed to the written duty).
    pub accepted: u32,
    /// Writes rejected (injected faults, duties above the maximum).
    pub rejected: u32,
    /// Accepted writes of duty 0: output low, no pulses.
    pub off: u32,
    /// Writes whose pulse lies outside the servo's pulse limits (by more than
    /// half a count), or above the maximum duty.
    pub violations: u32,
    /// The first duty accepted, if any.
    pub first: Option<u16>,
    /// The duty the output is producing now (0 before the first write:
    /// the output starts low).
    pub current: u16,
    /// Periods set after the first (changes of `servo rate`).
    pub periods: u32,
}

/// One servo's PWM output in the emulated board.
///
/// The channel models a 16-bit PWM slice like the Pico's: `max_duty` counts
/// make up the PWM period, so a duty of `d` is a pulse of
/// `d · period / max_duty`.
#[derive(Debug)]
pub struct VirtualPwm {
    max_duty: u16,
    period: Microseconds,
    /// Smallest and largest duty whose pulse is within the servo's limits.
    allowed: (u16, u16),
    /// The pulse range judged (for a new period's duties).
    judged: (Microseconds, Microseconds),
    inject: bool,
    log: ChannelLog,
}

impl VirtualPwm {
    /// A channel of `max_duty` counts per `period` driving a servo with
    /// calibration `servo`. It judges every pulse against the hard bounds
    /// no setting may pass ([`bounds`]) and, tighter, the servo's own pulse
    /// range: the calibration the head starts with, or the one in effect
    /// once the hooks say it changed ([`VirtualPwm::judge`]).
    pub const fn new(max_duty: u16, period: Microseconds, servo: &ServoCalibration) -> Self {
        Self {
            max_duty,
            period,
            allowed: allowed_duties(max_duty, period, servo.min_pulse, servo.max_pulse),
            judged: (servo.min_pulse, servo.max_pulse),
            inject: false,
            log: ChannelLog {
                accepted: 0,
                rejected: 0,
                off: 0,
                violations: 0,
                first: None,
                current: 0,
                periods: 0,
            },
        }
    }

    /// Judges the following pulses against `servo`'s pulse range (the
    /// calibration now in effect), within the hard bounds.
    pub fn judge(&mut self, servo: &ServoCalibration) {
        let min = if servo.min_pulse.0 < bounds::MIN_PULSE.0 {
            bounds::MIN_PULSE
        } else {
            servo.min_pulse
        };
        let max = if servo.max_pulse.0 > bounds::MAX_PULSE.0 {
            bounds::MAX_PULSE
        } else {
            servo.max_pulse
        };
        self.judged = (min, max);
        self.allowed = allowed_duties(self.max_duty, self.period, min, max);
    }

    /// Makes every following write fail (`true`) or succeed again (`false`).
    pub fn inject_faults(&mut self, on: bool) {
        self.inject = on;
    }

    /// What the channel saw so far.
    pub const fn log(&self) -> &ChannelLog {
        &self.log
    }

    /// The pulse a duty produces, in ns (rounded down).
    pub const fn pulse_ns(&self, duty: u16) -> u64 {
        duty as u64 * self.period.0 as u64 * 1000 / self.max_duty as u64
    }
}

/// The duties whose pulse lies within `[min, max]` give or take half a count
/// (the driver rounds pulses to the nearest count).
///
/// A duty `d` is a pulse of `d · P / M` (P: period, M: counts per period).
/// It is allowed if `d · P ≥ min · M − P/2` and `d · P ≤ max · M + P/2`,
/// i.e. `2·d·P ≥ 2·min·M − P` and `2·d·P ≤ 2·max·M + P`. (All in µs · counts,
/// below 2^50: u64.)
const fn allowed_duties(
    max_duty: u16,
    period: Microseconds,
    min: Microseconds,
    max: Microseconds,
) -> (u16, u16) {
    let m = max_duty as u64;
    let p = period.0 as u64;
    if p == 0 {
        return (1, 0); // empty: every pulse is a violation
    }
    // Smallest d with 2·d·P ≥ 2·min·M − P.
    let lo_num = (2 * min.0 as u64 * m).saturating_sub(p);
    let lo = lo_num.div_ceil(2 * p);
    // Largest d with 2·d·P ≤ 2·max·M + P.
    let hi = (2 * max.0 as u64 * m + p) / (2 * p);
    let hi = if hi > m { m } else { hi };
    (lo as u16, hi as u16)
}

/// The Pico's slice at `period`: its counts per period, from the next
/// write on (the frame driver counts the duties in them).
impl SetPeriod for VirtualPwm {
    fn set_period(&mut self, period: Microseconds) -> Result<(), Self::Error> {
        let Ok(clock) = SliceClock::for_period(PICO_SYS_HZ, period) else {
            return Err(VirtualPwmError::Period);
        };
        if (clock.top, period) == (self.max_duty, self.period) {
            return Ok(());
        }
        self.max_duty = clock.top;
        self.period = period;
        let (min, max) = self.judged;
        self.allowed = allowed_duties(self.max_duty, period, min, max);
        self.log.periods += 1;
        Ok(())
    }
}

impl ErrorType for VirtualPwm {
    type Error = VirtualPwmError;
}

impl SetDutyCycle for VirtualPwm {
    fn max_duty_cycle(&self) -> u16 {
        self.max_duty
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        if self.inject {
            self.log.rejected += 1;
            return Err(VirtualPwmError::Injected);
        }
        if duty > self.max_duty {
            self.log.rejected += 1;
            self.log.violations += 1;
            return Err(VirtualPwmError::AboveMax);
        }
        self.log.accepted += 1;
        if self.log.first.is_none() {
            self.log.first = Some(duty);
        }
        self.log.current = duty;
        if duty == 0 {
            // Output held low: no pulse, the servo goes limp. Not a violation.
            self.log.off += 1;
        } else if duty < self.allowed.0 || duty > self.allowed.1 {
            self.log.violations += 1;
        }
        Ok(())
    }
}
