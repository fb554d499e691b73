//! The board-neutral firmware layer of idle-head: what every board runs
//! around the hardware-free core (`idle_head_core`), written once.
//!
//! - [`frame`]: the embassy frame task's loop, the loop generator and the
//!   exchange of loop sets between them.
#![no_std]
#![deny(missing_docs)]
#![warn(clippy::pedantic)]
#![allow(
    clippy::module_name_repetitions,
    clippy::cast_possible_truncation,
    clippy::cast_possible_wrap,
    clippy::cast_sign_loss,
    clippy::cast_lossless,
    clippy::cast_precision_loss
)]

pub mod frame;
