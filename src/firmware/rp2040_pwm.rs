//! Clocking of an RP2040 PWM slice for servo pulses, worked out in `const fn`s.
//!
//! A slice counts from 0 to `TOP` and wraps, one count every `DIV` system
//! clock cycles, where `DIV` is an 8.4 fixed-point divider (`INT + FRAC/16`,
//! 1 ≤ `DIV` < 256). The output is high while the count is below the
//! channel's compare value, so a pulse is `compare` counts long and the PWM
//! period is `(TOP + 1) · DIV` system clock cycles.
//!
//! For the finest pulse resolution at a given PWM rate the counter should
//! count as fast as possible, i.e. `DIV` as small as possible such that the
//! period still fits the 16-bit counter (`TOP + 1 ≤ 65 536`):
//!
//! - 125 MHz system clock, 50 Hz: 125 000 000 / 50 = 2 500 000 cycles per
//!   period; 2 500 000 / 65 536 = 38.15, so `DIV` ≥ 38.15.
//! - In sixteenths: 2 500 000 · 16 / 65 536 = 610.35 → 611/16 = 38 + 3/16 =
//!   38.1875 (610/16 = 38.125 would need 65 574 counts, too many).
//! - Counts per period: 2 500 000 / 38.1875 = 65 466.4 → 65 466, `TOP` = 65 465.
//! - One count: 38.1875 / 125 MHz = 305.5 ns, the pulse resolution.
//! - The period: 65 466 · 305.5 ns = 19 999.86 µs (50.0003 Hz, 7 ppm fast):
//!   a servo decodes the pulse width, not the frame rate, so the rate only
//!   has to be near 50 Hz.
//!
//! With a fractional `DIV` the RP2040 spaces the counts 38 or 39 cycles
//! apart so that they average 38.1875 cycles: a pulse edge moves by at most
//! one system clock cycle (8 ns), far below a servo's dead band (~1 µs).
//!
//! `embedded_hal::pwm::SetDutyCycle::max_duty_cycle` of an embassy-rp output
//! is `TOP` (65 465). The frame driver maps the servo period (20 000 µs) to
//! that many counts, so a written pulse is short by at most 20 000 µs ·
//! (1 − 65 465 · 305.5 ns / 20 000 µs) / 20 000 µs ≈ 22 ppm of its width,
//! 0.05 µs at 2000 µs: below one count.

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
    /// `pwm_hz` from a `sys_hz` system clock (counts per period rounded to
    /// the nearest whole count).
    ///
    /// # Errors
    /// [`RateUnreachable`] if no divider in 1..256 brings the period into
    /// the 16-bit counter (or into at least two counts), or a rate is zero.
    pub const fn finest(sys_hz: u32, pwm_hz: u32) -> Result<Self, RateUnreachable> {
        if sys_hz == 0 || pwm_hz == 0 {
            return Err(RateUnreachable);
        }
        // Cycles per period in sixteenths: < 2^32 · 16, fits u64.
        let cycles_16 = sys_hz as u64 * 16 / pwm_hz as u64;
        // First candidate: ⌈cycles · 16 / 65 536⌉, then step up past rounding.
        let mut div = cycles_16.div_ceil(MAX_COUNTS);
        if div < MIN_DIVIDER_16THS {
            div = MIN_DIVIDER_16THS;
        }
        while div <= MAX_DIVIDER_16THS {
            // Nearest whole number of counts per period.
            let counts = (cycles_16 + div / 2) / div;
            if counts <= MAX_COUNTS {
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

/// Servo PWM rate: 50 Hz (a 20 ms period).
pub const SERVO_PWM_HZ: u32 = 50;

/// Slice clock of the Pico's servo outputs: 125 MHz → 50 Hz.
pub const PICO_SERVO_CLOCK: SliceClock = match SliceClock::finest(PICO_SYS_HZ, SERVO_PWM_HZ) {
    Ok(c) => c,
    Err(_) => panic!("no 8.4 divider runs a 16-bit PWM slice at 50 Hz from 125 MHz"),
};

// The numbers worked out in the module docs.
const _: () = {
    assert!(PICO_SERVO_CLOCK.divider_int() == 38 && PICO_SERVO_CLOCK.divider_frac() == 3);
    assert!(PICO_SERVO_CLOCK.top == 65_465);
    assert!(PICO_SERVO_CLOCK.count_ps(PICO_SYS_HZ) == 305_500);
    assert!(PICO_SERVO_CLOCK.period_ns(PICO_SYS_HZ) == 19_999_863);
};
