//! Clocking of an RP2040 PWM slice for servo pulses, worked out in `const fn`s
//! (and at run time, when `servo rate` changes the period).
//!
//! The PWM period is made exactly one frame ([`SliceClock::for_period`]):
//! every frame is a whole number of µs and of system clock cycles, and the
//! divider is the smallest 8.4 fixed-point one that gives a whole number of
//! counts per period within the 16-bit counter (at 50 Hz on 125 MHz: 39.0625,
//! `TOP` = 63 999, 312.5 ns a count).
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Clocking a PWM slice”).

use crate::units::Microseconds;

/// A frame's duty goes out at the PWM wrap a period over this after the
/// frame's deadline (a tenth: 2 ms of a 20 ms frame): the boards set the
/// phase of their PWM so (`crates/rp/src/pwm.rs`), and a frame written later
/// than that misses its pulse ([`FrameClock::with_latch_divisor`]).
///
/// [`FrameClock::with_latch_divisor`]: crate::driver::FrameClock::with_latch_divisor
pub const WRAP_MARGIN_DIVISOR: u32 = 10;

/// Clock settings of one PWM slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SliceClock {
    /// Divider in sixteenths (`INT · 16 + FRAC`), 16..=4095.
    pub divider_16ths: u16,
    /// Wrap value: the period is `top + 1` counts.
    pub top: u16,
}

/// No 8.4 divider gives the requested rate with a 16-bit counter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RateUnreachable;

/// Largest divider: 255 + 15/16.
const MAX_DIVIDER_16THS: u64 = 0xFFF;
/// Smallest divider: 1.
const MIN_DIVIDER_16THS: u64 = 16;
/// The counter is 16 bits wide: at most 65 536 counts per period.
const MAX_COUNTS: u64 = 1 << 16;

impl SliceClock {
    /// The smallest divider, and the `TOP` for it, that runs a slice at
    /// exactly `pwm_hz` from a `sys_hz` system clock: a whole number of
    /// counts per period, of whole sixteenths of a cycle each.
    ///
    /// # Errors
    /// [`RateUnreachable`] if a rate is zero, the period is not a whole
    /// number of sixteenths of a cycle, or no divider in 1..256 splits it
    /// into at most 65 536 (and at least two) whole counts.
    pub const fn exact(sys_hz: u32, pwm_hz: u32) -> Result<Self, RateUnreachable> {
        if sys_hz == 0 || pwm_hz == 0 {
            return Err(RateUnreachable);
        }
        // Cycles per period in sixteenths: < 2^32 · 16, fits u64.
        let cycles_16 = sys_hz as u64 * 16;
        if !cycles_16.is_multiple_of(pwm_hz as u64) {
            return Err(RateUnreachable);
        }
        Self::split(cycles_16 / pwm_hz as u64)
    }

    /// The smallest divider, and the `TOP` for it, that make a period of
    /// exactly `period` µs from a `sys_hz` system clock (as
    /// [`exact`](Self::exact)); a `servo rate` change works it out at run
    /// time, between two frames (tens of `u32` remainders at the most for
    /// the boards' clocks).
    ///
    /// ```
    /// use idle_head_core::pwm_clock::{PICO_SYS_HZ, SliceClock};
    /// use idle_head_core::Microseconds;
    /// let clock = SliceClock::for_period(PICO_SYS_HZ, Microseconds(3003)).unwrap();
    /// assert_eq!((clock.divider_int(), clock.divider_frac(), clock.top), (6, 4, 60_059));
    /// assert_eq!(clock.period_ns(PICO_SYS_HZ), 3_003_000);
    /// ```
    ///
    /// # Errors
    /// [`RateUnreachable`] if the period is not a whole number of
    /// sixteenths of a cycle, or no divider in 1..256 splits it into at
    /// most 65 536 (and at least two) whole counts.
    pub const fn for_period(sys_hz: u32, period: Microseconds) -> Result<Self, RateUnreachable> {
        // sys_hz · 16 · period < 2^32 · 2^4 · 2^32: fits u128, and u64
        // once divided by 10^6 (for any period below 70 minutes).
        let cycles_16 = sys_hz as u128 * 16 * period.0 as u128;
        if cycles_16 == 0 || !cycles_16.is_multiple_of(1_000_000) {
            return Err(RateUnreachable);
        }
        let cycles_16 = cycles_16 / 1_000_000;
        if cycles_16 > u64::MAX as u128 {
            return Err(RateUnreachable);
        }
        Self::split(cycles_16 as u64)
    }

    /// The smallest divider (in sixteenths, within 1..256) that splits
    /// `cycles_16` sixteenths of a cycle into whole counts of at most 65 536
    /// (and at least two), with its `TOP`: in `u32` when the period fits it
    /// (every servo period of the boards), a library call less per try on
    /// the Cortex-M0+.
    const fn split(cycles_16: u64) -> Result<Self, RateUnreachable> {
        // The fewest sixteenths that fit the counter, then up to the first
        // that divides the period.
        let mut div = cycles_16.div_ceil(MAX_COUNTS);
        if div < MIN_DIVIDER_16THS {
            div = MIN_DIVIDER_16THS;
        }
        while div <= MAX_DIVIDER_16THS {
            let divides = if cycles_16 <= u32::MAX as u64 {
                (cycles_16 as u32).is_multiple_of(div as u32)
            } else {
                cycles_16.is_multiple_of(div)
            };
            if divides {
                let counts = if cycles_16 <= u32::MAX as u64 {
                    (cycles_16 as u32 / div as u32) as u64
                } else {
                    cycles_16 / div
                };
                if counts < 2 {
                    return Err(RateUnreachable);
                }
                return Ok(Self {
                    divider_16ths: div as u16,
                    top: (counts - 1) as u16,
                });
            }
            div += 1;
        }
        Err(RateUnreachable)
    }

    /// Integer part of the divider (`DIV_INT`).
    #[must_use]
    pub const fn divider_int(&self) -> u8 {
        (self.divider_16ths >> 4) as u8
    }

    /// Fractional part of the divider in sixteenths (`DIV_FRAC`).
    #[must_use]
    pub const fn divider_frac(&self) -> u8 {
        (self.divider_16ths & 0xF) as u8
    }

    /// Duration of one count in picoseconds, rounded (`DIV / sys_hz`).
    #[must_use]
    pub const fn count_ps(&self, sys_hz: u32) -> u64 {
        // 10^12 ps/s · div/16 / sys_hz; 10^12 · 4095 < 2^52.
        let num = 1_000_000_000_000 * self.divider_16ths as u64;
        let den = 16 * sys_hz as u64;
        (num + den / 2) / den
    }

    /// The PWM period in nanoseconds, rounded (`(TOP + 1) · DIV / sys_hz`).
    #[must_use]
    pub const fn period_ns(&self, sys_hz: u32) -> u64 {
        let num = 1_000_000_000 * (self.top as u64 + 1) * self.divider_16ths as u64;
        let den = 16 * sys_hz as u64;
        (num + den / 2) / den
    }
}

/// The RP2040's default system clock (embassy-rp's `Config::default()`):
/// 125 MHz from the 12 MHz crystal through `PLL_SYS`.
pub const PICO_SYS_HZ: u32 = 125_000_000;

/// The RP2350's default system clock (embassy-rp's `Config::default()`):
/// 150 MHz (the Pico 2).
pub const PICO2_SYS_HZ: u32 = 150_000_000;

/// Servo PWM rate: 50 Hz (a 20 ms period).
pub const SERVO_PWM_HZ: u32 = 50;

/// Slice clock of the Pico's servo outputs: 125 MHz → exactly 50 Hz.
pub const PICO_SERVO_CLOCK: SliceClock = match SliceClock::exact(PICO_SYS_HZ, SERVO_PWM_HZ) {
    Ok(c) => c,
    Err(_) => panic!("no 8.4 divider runs a 16-bit PWM slice at exactly 50 Hz from 125 MHz"),
};

/// Slice clock of the Pico 2's servo outputs: 150 MHz → exactly 50 Hz.
pub const PICO2_SERVO_CLOCK: SliceClock = match SliceClock::exact(PICO2_SYS_HZ, SERVO_PWM_HZ) {
    Ok(c) => c,
    Err(_) => panic!("no 8.4 divider runs a 16-bit PWM slice at exactly 50 Hz from 150 MHz"),
};

// The numbers worked out in the module docs (the QEMU images and the
// emulator check compile this file too).
const _: () = {
    assert!(PICO_SERVO_CLOCK.divider_int() == 39 && PICO_SERVO_CLOCK.divider_frac() == 1);
    assert!(PICO_SERVO_CLOCK.top == 63_999);
    assert!(PICO_SERVO_CLOCK.count_ps(PICO_SYS_HZ) == 312_500);
    assert!(PICO_SERVO_CLOCK.period_ns(PICO_SYS_HZ) == 20_000_000);
    let Ok(pico_333) = SliceClock::for_period(PICO_SYS_HZ, Microseconds(3003)) else {
        panic!("no clock for 3003 µs at 125 MHz")
    };
    assert!(pico_333.divider_16ths == 100 && pico_333.top == 60_059);
    assert!(pico_333.count_ps(PICO_SYS_HZ) == 50_000);
    let Ok(pico2_333) = SliceClock::for_period(PICO2_SYS_HZ, Microseconds(3003)) else {
        panic!("no clock for 3003 µs at 150 MHz")
    };
    assert!(pico2_333.divider_16ths == 110 && pico2_333.top == 65_519);
    // 50 Hz by period is 50 Hz by rate.
    assert!(
        PICO_SERVO_CLOCK.top
            == match SliceClock::for_period(PICO_SYS_HZ, Microseconds(20_000)) {
                Ok(c) => c.top,
                Err(_) => 0,
            }
    );
    // Every rate of `servo rate` has a clock on both boards.
    let mut hz = crate::servo::ServoRate::MIN.hz();
    while hz <= crate::servo::ServoRate::MAX.hz() {
        if let Some(rate) = crate::servo::ServoRate::new(hz) {
            assert!(SliceClock::for_period(PICO_SYS_HZ, rate.period()).is_ok());
            assert!(SliceClock::for_period(PICO2_SYS_HZ, rate.period()).is_ok());
        }
        hz += 1;
    }
};
