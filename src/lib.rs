//! Idle-loop head motion for a three-servo animatronic head.
//!
//! This crate is the hardware-free core (`no_std`, no allocation, no `unsafe`):
//! motion generation after Kocoń's idle-loop method, servo mapping and frame
//! playback. The Raspberry Pi Pico image is `src/bin/pico/`; the QEMU images
//! are a package of their own, `qemu/`, with the emulated board's memory map.
#![no_std]
#![forbid(unsafe_code)]
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

pub mod axis;
pub mod driver;
#[cfg(feature = "firmware")]
pub mod firmware;
pub mod metrics;
pub mod motion;
pub mod playback;
pub mod servo;
pub mod units;

pub use axis::Axis;
pub use driver::{DriverConfig, FrameClock, FrameDriver, FrameReport};
pub use playback::{LoopSource, Playback};
pub use servo::{Direction, PwmTiming, ServoCalibration};
pub use units::{Angle, AngleRange, Microseconds, Millis};
