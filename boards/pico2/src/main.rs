//! Raspberry Pi Pico 2 (RP2350) firmware, first step: the board boots,
//! clocks the three servo outputs at exactly 50 Hz and holds each servo at
//! its neutral pulse. The idle motion, the console and the settings come
//! with the shared firmware layer.
//!
//! `cargo run --release` in this folder flashes it (see
//! `.cargo/config.toml`); `cargo xtask uf2 --board pico2` writes the UF2 to
//! copy onto the board in BOOTSEL mode. No emulator runs the RP2350 here:
//! `cargo xtask test` builds this image and checks where it is linked, and
//! only a board runs it.
//!
//! # Wiring (as on the Pico: the boards share their pinout)
//!
//! | axis  | GPIO | Pico 2 pin | PWM slice, channel |
//! |-------|------|------------|--------------------|
//! | pitch | GP16 | 21         | PWM0 A             |
//! | roll  | GP18 | 24         | PWM1 A             |
//! | yaw   | GP20 | 26         | PWM2 A             |
//!
//! # PWM timing
//!
//! 150 MHz system clock (embassy-rp's default on the RP2350: the 12 MHz
//! crystal through `PLL_SYS`, 12 MHz · 125 / 5 / 2), exactly 50 Hz: divider
//! 46 + 14/16 = 46.875, `TOP` = 63 999, one count = 312.5 ns as on the Pico
//! (worked out by `idle_head_core::pwm_clock::SliceClock::exact`).
#![no_std]
#![no_main]

use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_rp::Peri;
use embassy_rp::pwm::{ChannelAPin, Config, Pwm, Slice};
use fixed::FixedU16;
use fixed::types::extra::U4;
use idle_head_core::driver::DriverConfig;
use idle_head_core::pwm_clock::{SERVO_PWM_HZ, SliceClock};
use idle_head_core::servo::ServoCalibration;
use idle_head_core::{Axis, Microseconds};

/// The RP2350's system clock in embassy-rp's default configuration.
const SYS_HZ: u32 = 150_000_000;

/// The servo slices' clock: 150 MHz → exactly 50 Hz.
const SERVO_CLOCK: SliceClock = match SliceClock::exact(SYS_HZ, SERVO_PWM_HZ) {
    Ok(clock) => clock,
    Err(_) => panic!("no 8.4 divider runs a 16-bit PWM slice at exactly 50 Hz from 150 MHz"),
};

/// The Pico's servos, pulses and PWM period.
const CONFIG: DriverConfig = DriverConfig::DEFAULT;

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_rp::init(embassy_rp::config::Config::default());
    let sys_hz = embassy_rp::clocks::clk_sys_freq();
    if sys_hz != SYS_HZ {
        // The servo period would be wrong: no pulses at all (the pins stay
        // low) rather than pulses a servo misreads.
        defmt::error!(
            "system clock {=u32} Hz, not {=u32}: the servo outputs stay off",
            sys_hz,
            SYS_HZ
        );
        return;
    }
    let [pitch, roll, yaw] = CONFIG.servos;
    let _outputs = [
        neutral(p.PWM_SLICE0, p.PIN_16, &pitch),
        neutral(p.PWM_SLICE1, p.PIN_18, &roll),
        neutral(p.PWM_SLICE2, p.PIN_20, &yaw),
    ];
    defmt::info!(
        "Pico 2: servos on GP16 (PWM0 A), GP18 (PWM1 A), GP20 (PWM2 A); {=u32} Hz system clock, divider {=u8}+{=u8}/16, TOP {=u16}, {=u64} ps per count, period {=u64} ns",
        sys_hz,
        SERVO_CLOCK.divider_int(),
        SERVO_CLOCK.divider_frac(),
        SERVO_CLOCK.top,
        SERVO_CLOCK.count_ps(SYS_HZ),
        SERVO_CLOCK.period_ns(SYS_HZ)
    );
    for (axis, servo) in Axis::ALL.iter().zip(CONFIG.servos.iter()) {
        defmt::info!(
            "{=str}: holding neutral, {=u32} us = {=u16} counts",
            axis.name(),
            servo.neutral.0,
            counts(servo.neutral)
        );
    }
    // The outputs run on their own; this task only keeps them.
    core::future::pending::<()>().await;
}

/// PWM counts of `pulse`, as the frame driver maps it: the servo period
/// is `TOP` counts.
const fn counts(pulse: Microseconds) -> u16 {
    CONFIG.pwm.duty(pulse, SERVO_CLOCK.top).0
}

/// Channel A of `slice` on `pin`, at 50 Hz, sending `servo`'s neutral pulse.
fn neutral<S: Slice>(
    slice: Peri<'static, S>,
    pin: Peri<'static, impl ChannelAPin<S>>,
    servo: &ServoCalibration,
) -> Pwm<'static> {
    let mut config = Config::default();
    config.divider = FixedU16::<U4>::from_bits(SERVO_CLOCK.divider_16ths);
    config.top = SERVO_CLOCK.top;
    config.compare_a = counts(servo.neutral);
    Pwm::new_output_a(slice, pin, config)
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    defmt::error!("panic: halted (the probe's backtrace shows where)");
    // A usage fault, escalated to a hard fault: probe-rs stops there and
    // prints the backtrace.
    cortex_m::asm::udf()
}
