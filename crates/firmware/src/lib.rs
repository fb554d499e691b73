//! The board-neutral firmware layer of idle-head: what every board runs
//! around the hardware-free core (`idle_head_core`), written once.
//!
//! - [`boot`]: the boot sequence before the first frame, and the firmware's
//!   singletons (command queue, console link, loop set buffers).
//! - [`config`]: the built-in configuration every board starts from.
//! - [`frame`]: the frame task's loop, one frame every 20 ms; [`tasks`]: its
//!   body and the loop generator task.
//! - [`exchange`]: the loop sets' round between the frame task and the loop
//!   generator, which makes each next set in the background.
//! - [`hooks`]: the watchdog of a board running on its own; [`report`]: its
//!   status log once a loop, below every other task.
//! - [`console`]: the console's loop over a board's byte [`console::Port`]
//!   (a Bottango driver on a port after a Bottango handshake).
//! - [`dmx`]: the DMX512 receiver ([`dmx::Receiver`]), fed by a board's UART.
//! - [`input`]: the trigger inputs' task over a board's [`input::InputSource`].
//! - [`radar`]: the radar's receiver, fed by a board's UART or PIO.
//! - [`storage`]: the settings store in a board's flash.
//!
//! What a board adds is its hardware: the PWM outputs, the ports, the flash,
//! the watchdog, the executors (see `idle-head-rp`, `boards/qemu`).
#![cfg_attr(not(test), no_std)]

pub mod boot;
#[cfg(feature = "calibrate")]
pub mod calibrate;
pub mod config;
pub mod console;
pub mod dmx;
pub mod exchange;
pub mod frame;
pub mod hooks;
pub mod input;
pub mod log;
pub mod radar;
pub mod report;
pub mod storage;
pub mod tasks;
