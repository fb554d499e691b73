//! The frame driver: loop offsets in, three servo duties out, safely.
//!
//! Per frame and per servo (pitch, roll, yaw):
//!
//! 1. the trajectory offset is scaled by the fade envelope (smoothstep fade-in
//!    after [`FrameDriver::start`], fade-out after [`FrameDriver::request_stop`]);
//! 2. added to the neutral pose and clamped to the axis' mechanical limits;
//! 3. followed within the axis' speed and acceleration limits;
//! 4. converted to a pulse (clamped to the servo's pulse limits) and duty ticks;
//! 5. written; a write error is counted and reported, the other servos carry on
//!    and the servo is written again next frame, its limiter continuing from
//!    the last pulse it actually received; a servo whose writes fail for
//!    [`FaultPolicy::disable_after`] in a row gets duty 0 once (no pulses:
//!    it goes limp) and is never written again.
//!
//! The first pulse any servo receives is its neutral pulse (0°).
//!
//! Configuration is in physical units ([`DriverConfig`]); [`DriverConfig::build`]
//! validates it into the integer [`DriverParams`] the frame path uses.
//! [`FrameDriver::set_motion_limits`] and [`FrameDriver::set_servo`] change
//! an axis' limits or calibration at run time, validated the same way, and
//! [`FrameDriver::set_pwm_period`] with [`FrameDriver::set_frame_period`]
//! the servos' rate (`servo rate`, see `frame/rate.rs`).
//! [`FrameClock`] keeps the frame deadlines and the frames' time, and
//! skips late frames.
//!
//! Everything physical is in time, not frames: the limits in °/s and
//! °/s², the fade and the fault policy in ms. Their per-frame forms are
//! worked out for the frame period, and again when it changes.
//!
//! # Cost
//!
//! The frame path is 32-bit integer arithmetic without divisions in the
//! common case: the fade gain is a smoothstep of a level kept as a whole part
//! and a remainder (`envelope`), the limiter follows a target that moves
//! within the limits with two comparisons and brakes exactly with two `u32`
//! divisions and a `u32` square root otherwise (`limiter`), and each servo
//! maps its angle to a pulse and a duty with a [`ServoMap`](crate::servo::ServoMap)
//! worked out when the driver is made (it needs the channel's maximum duty).

mod clock;
mod config;
mod envelope;
mod error;
mod frame;
mod limiter;
mod report;

pub use crate::units::{DegreesPerSecond, DegreesPerSecondSquared};
pub use clock::{FrameClock, FrameTick, ZeroPeriod};
pub use config::{DriverConfig, DriverParams, FaultPolicy, MotionLimits};
pub use envelope::START_HOLD;
pub use error::{ConfigError, RateError};
pub use frame::FrameDriver;
pub use report::{DriverStats, FrameReport, Outcome, ServoReport};

pub(crate) use config::slew_rates;
pub(crate) use limiter::SlewRates;
