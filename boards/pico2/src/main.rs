//! Raspberry Pi Pico 2 (RP2350): three servos play the idle loop, with the
//! console on UART0 and USB and the settings in flash, as on the Pico.
//!
//! `cargo run --release` in this folder flashes it (see
//! `.cargo/config.toml`); `cargo xtask uf2 --board pico2` writes the UF2 to
//! copy onto the board in BOOTSEL mode. What runs is the same on every board
//! (`idle-head-firmware`, with `idle-head-rp` for the RP chips); a board
//! file only says which board it is and where its pins go: the Pico 2 keeps
//! the Pico's pinout (`idle_head_rp::pico`). No emulator runs the RP2350
//! here: `cargo xtask test` builds this image and checks where it is
//! linked, and only a board runs it.
//!
//! 150 MHz system clock (embassy-rp's default on the RP2350), so the servo
//! slices divide by 46 + 14/16 for exactly 50 Hz (`idle_head_rp::SERVO_CLOCK`).
//! `memory.x`: 4 MiB of flash, the last 16 KiB kept for the settings store,
//! 512 KiB of RAM; embassy-rp links the block the boot ROM starts the image
//! from (IMAGE_DEF, a Secure Arm executable) into `.start_block`.
#![no_std]
#![no_main]

use defmt_rtt as _;
use embassy_executor::Spawner;

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_rp::init(embassy_rp::config::Config::default());
    let board = idle_head_rp::pico::board(p, "Raspberry Pi Pico 2 (RP2350)");
    idle_head_rp::start(spawner, board);
}
