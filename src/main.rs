//! Raspberry Pi Pico (RP2040): three servos play the idle loop, with the
//! console on UART0 and USB and the settings in flash.
//!
//! `cargo run --release` builds this image and flashes it (as a UF2 onto a
//! Pico in BOOTSEL mode, or through a debug probe with probe-rs); the log
//! arrives over RTT (defmt). What runs is the same on every board
//! (`idle-head-firmware`, with `idle-head-rp` for the RP chips); a board
//! file only says which board it is and where its pins go: here the Pico's
//! own pinout (`idle_head_rp::pico`: servos on GP16, GP18 and GP20, the
//! console on UART0 at GP0/GP1 and on USB).
//!
//! `memory.x`: 2 MiB of flash, the last 16 KiB kept for the settings store,
//! and 256 KiB of RAM; `build.rs` links the second-stage bootloader the
//! RP2040 boot ROM loads from the first 256 bytes of flash.
#![no_std]
#![no_main]

use defmt_rtt as _;
use embassy_executor::Spawner;

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_rp::init(embassy_rp::config::Config::default());
    let board = idle_head_rp::pico::board(p, "Raspberry Pi Pico (RP2040)");
    idle_head_rp::start(spawner, board);
}
