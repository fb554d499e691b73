//! The smallest board: a Raspberry Pi Pico with three servos and the
//! console on USB, and nothing else (no UART console, no settings store,
//! no DMX, no trigger inputs, no radar). It runs the same firmware as the
//! full Pico image: the idle plays on the built-in settings, the console
//! answers on USB, and the commands for the parts it lacks answer
//! `err unavailable` (`docs/dev/adding-a-board.md`).
//!
//! `cargo build --release --example minimal` builds it (`cargo xtask test`
//! does); `cargo run --release --example minimal` flashes it like the Pico
//! image. It links with the Pico's `memory.x` and `build.rs`.
#![no_std]
#![no_main]

// ANCHOR: board
use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_rp::usb;
use idle_head_rp::pwm::ServoPwm;
use idle_head_rp::{Board, Irqs, SERVO_CLOCK};

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_rp::init(embassy_rp::config::Config::default());
    // Each servo on a PWM slice of its own (GPIO n is slice n/2 mod 8).
    let servos = [
        ServoPwm::new(p.PWM_SLICE0, p.PIN_16, &SERVO_CLOCK),
        ServoPwm::new(p.PWM_SLICE1, p.PIN_18, &SERVO_CLOCK),
        ServoPwm::new(p.PWM_SLICE2, p.PIN_20, &SERVO_CLOCK),
    ];
    let board = Board::new(
        "minimal Pico (servos and USB only)",
        servos,
        "pitch GP16 (PWM0 A), roll GP18 (PWM1 A), yaw GP20 (PWM2 A)",
        p.WATCHDOG,
    )
    .with_usb(usb::Driver::new(p.USB, Irqs));
    idle_head_rp::start(spawner, board);
}
// ANCHOR_END: board
