//! The hardware-free core of the idle-head firmware (`no_std`, no
//! allocation, no `unsafe`): motion generation after Kocoń's idle-loop method
//! ([`motion`]), servo mapping ([`servo`]), frame playback ([`playback`]) and
//! the frame driver ([`driver`]). The Raspberry Pi Pico image is
//! `src/main.rs`; the QEMU images are a package of their own, `boards/qemu/`.
//!
//! ```
//! use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadTrajectories, Mdeg16};
//! use idle_head_core::{Angle, Axis, LoopSource};
//!
//! // The three loops of the paper's Table 2 set, as the firmware computes them at boot.
//! let mut head: HeadTrajectories<Mdeg16, DEFAULT_N> = HeadTrajectories::new();
//! head.generate(&DEFAULT_HEAD).unwrap();
//! let yaw = head.axis(Axis::Yaw);
//! assert_eq!(yaw.angle(0), Angle::ZERO); // every loop starts at the neutral pose
//! let range = DEFAULT_HEAD.yaw.range;
//! assert!((0..DEFAULT_N).all(|i| range.contains(yaw.angle(i))));
//! ```
//!
//! The hardware, the wiring, the commands and how the motion is computed are
//! in the project's book (`docs/`, built by `cargo xtask book`): the user
//! guide for the hardware and the console, the design notes for the method.
#![cfg_attr(not(test), no_std)]
// The core holds no unsafe code (the other lints are the workspace's, in
// crates/Cargo.toml).
#![forbid(unsafe_code)]

// A bare `cargo test` builds for the firmware's target, where no test can
// run: say where the tests are instead of failing on each doc test.
#[cfg(all(doctest, target_os = "none"))]
compile_error!("the tests run on the host: `cargo xtask test` (or `cd host-tests && cargo test`)");

pub mod axis;
pub mod behaviour;
pub mod bottango;
pub mod command;
pub mod console;
pub mod dmx;
pub mod driver;
pub mod gestures;
pub mod idle;
pub mod input;
pub mod metrics;
pub mod motion;
pub mod playback;
pub mod pwm_clock;
pub mod ring;
pub mod seed;
pub mod servo;
pub mod settings;
pub mod shared;
pub mod text;
pub mod track;
pub mod units;

pub use axis::Axis;
pub use driver::{DriverConfig, FrameClock, FrameDriver, FrameReport};
pub use playback::{LoopSource, Playback};
pub use servo::{Direction, PwmTiming, ServoCalibration};
pub use units::{Angle, AngleRange, Microseconds, Millimetres, Millis, Timestamp};
