//! Raspberry Pi Pico (RP2040): three servos play the idle loop, with the
//! console on UART0 and USB and the settings in flash.
//!
//! `cargo run --release` builds this image and flashes it (through a debug
//! probe with probe-rs, or as a UF2 onto a Pico in BOOTSEL mode); the log
//! arrives over RTT (defmt). What runs is the same on every board
//! (`idle-head-firmware`, with `idle-head-rp` for the RP chips); this file
//! only says which pins and peripherals go where.
//!
//! # Wiring
//!
//! | what        | GPIO       | Pico pin | peripheral         |
//! |-------------|------------|----------|--------------------|
//! | pitch servo | GP16       | 21       | PWM0 A             |
//! | roll servo  | GP18       | 24       | PWM1 A             |
//! | yaw servo   | GP20       | 26       | PWM2 A             |
//! | console TX  | GP0        | 1        | UART0, 115200 8N1  |
//! | console RX  | GP1        | 2        | UART0              |
//! | console     | USB        |          | CDC-ACM serial port|
//!
//! (GPIO n drives PWM slice ⌊n/2⌋ mod 8, channel A for even n.) One slice
//! per servo, so each output starts on its own first valid pulse
//! (`idle_head_rp::pwm`). Servo signal wires to these pins, servo ground to
//! a Pico GND (e.g. pin 23) and to the servo supply's ground; power the
//! servos from their own 5 to 6 V supply, not from the Pico.
//!
//! # Memory
//!
//! `memory.x`: 2 MiB of flash, the last 16 KiB kept for the settings store,
//! and 256 KiB of RAM.
#![no_std]
#![no_main]

use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_rp::peripherals::{UART0, USB};
use embassy_rp::{bind_interrupts, uart, usb};
use idle_head_rp::pwm::ServoPwm;
use idle_head_rp::{Board, SERVO_CLOCK};

bind_interrupts!(struct Irqs {
    UART0_IRQ => uart::BufferedInterruptHandler<UART0>;
    USBCTRL_IRQ => usb::InterruptHandler<USB>;
});

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_rp::init(embassy_rp::config::Config::default());
    // The outputs stay low from here until the first frame.
    let servos = [
        ServoPwm::new(p.PWM_SLICE0, p.PIN_16, &SERVO_CLOCK),
        ServoPwm::new(p.PWM_SLICE1, p.PIN_18, &SERVO_CLOCK),
        ServoPwm::new(p.PWM_SLICE2, p.PIN_20, &SERVO_CLOCK),
    ];
    idle_head_rp::start(
        spawner,
        Board {
            name: "Raspberry Pi Pico (RP2040)",
            servos,
            servo_pins: "pitch GP16 (PWM0 A), roll GP18 (PWM1 A), yaw GP20 (PWM2 A)",
            uart: idle_head_rp::uart::console(p.UART0, p.PIN_0, p.PIN_1, Irqs),
            uart_pins: "UART0 GP0 TX, GP1 RX",
            usb: usb::Driver::new(p.USB, Irqs),
            flash: p.FLASH,
            watchdog: p.WATCHDOG,
        },
    );
}
