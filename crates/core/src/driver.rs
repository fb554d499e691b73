//! The frame driver: loop offsets in, three servo duties out, safely.
//!
//! Per frame and servo: the fade, the axis' mechanical limits, the speed
//! and acceleration limiter, the pulse limits, the write. No pulse leaves a
//! servo's limits, the first one is its neutral pulse, and a servo whose
//! writes keep failing ([`FaultPolicy::disable_after`]) goes limp and is
//! never written again. The configuration is in physical units
//! ([`DriverConfig`], validated into [`DriverParams`]); its per-frame forms
//! are worked out for the frame period, and again when it changes.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The frame driver”).

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
