//! Behaviour: gestures and gaze layered over the idle motion.
//!
//! ```text
//!  console, scripts ──try_submit──▶ CommandQueue ──drain (≤ 2 a frame)──┐
//!                                                                       ▼
//!  IdleSource ──idle offsets──▶ Mixer (gaze + idle·gain·duck + gestures) ──▶ Show ──▶ FrameDriver
//!                                   └── limit mode per axis (idle | gesture)   (DMX, Bottango)
//! ```
//!
//! - [`gesture`]: gestures as they play (human-like, C2 envelopes); which
//!   gestures there are is the [gesture table](crate::gestures), how each
//!   moves its [`shape`].
//! - [`glide`](self#gaze-and-idle-changes): minimum-jerk moves that start
//!   from any state (gaze, idle gain).
//! - [`gaze`]: `look` and `center`, holds and returns.
//! - [`mixer`]: where the layers meet, and the limit mode per axis.
//! - [`show`]: the show layer (DMX, Bottango) over all of it.
//! - [`config`]: [`BehaviourConfig`] in physical units, validated
//!   (`validate.rs`) into [`BehaviourParams`] ([`params`]).
//! - [`queue`]: the command queue; [`head`]: the frame engine.
//!
//! # Gaze and idle changes
//!
//! Both move along minimum-jerk glides that start from the current
//! position, velocity and acceleration (see `glide.rs`), so a new `look`
//! or `center` while the head moves, or an `idle amp` while the gain
//! changes, never jumps in angle, velocity or acceleration.
//!
//! # Fixed point
//!
//! The frame path is integer arithmetic with 32-bit multiplies only
//! (ARMv6-M has neither a 64-bit multiply nor a divide instruction):
//! fractions are Q16 (`u32`, 65 536 = 1) unless named Q32, angles are
//! millidegrees; every reciprocal is computed when an action is applied.
//!
//! ```
//! use idle_head_core::behaviour::{BehaviourConfig, Mixer};
//! use idle_head_core::command::{Action, GestureKind, GestureRequest};
//! use idle_head_core::driver::DriverConfig;
//! use idle_head_core::{Angle, Timestamp};
//!
//! let driver = DriverConfig::DEFAULT.build().unwrap();
//! let mut mixer = Mixer::new(BehaviourConfig::DEFAULT.build(&driver).unwrap());
//! mixer.apply(&Action::Gesture(GestureRequest::new(GestureKind::Nod))).unwrap();
//! // The default nod: 2 cycles at 2.5 Hz in 800 ms; its first dip peaks at 200 ms
//! // (frame 10 at 50 Hz) at 6.3° (6° × 1.05: a default amplitude rises with the
//! // number of cycles).
//! let frame = |k: u64| Timestamp(k * 20_000);
//! let pitch: Vec<i32> = (0..45)
//!     .map(|k| mixer.frame(frame(k), [Angle::ZERO; 3])[0].millidegrees())
//!     .collect();
//! assert_eq!(pitch[0], 0);
//! assert_eq!(pitch[10], 6300);
//! assert_eq!(pitch[40], 0);
//! ```

pub mod attention;
pub mod config;
pub mod error;
mod fixed;
pub mod follow;
pub mod gaze;
pub mod gesture;
mod glide;
pub mod head;
pub mod idle;
pub mod mixer;
pub mod params;
pub mod queue;
pub mod rest;
pub mod shape;
pub mod show;
pub mod tracker;
mod validate;

pub use crate::gestures::GestureDefaults;
pub use crate::units::MilliHertz;
pub use config::{BehaviourConfig, GazeConfig, IdleConfig, LiveConfig, RestConfig};
pub use error::BehaviourError;
pub use gaze::LookApplied;
pub use gesture::GesturePlan;
pub use head::{Head, HeadFrame};
pub use idle::{IdleSource, LOOP_DURATION};
pub use mixer::{Applied, Mixer};
pub use params::{BehaviourParams, LimitMode};
pub use queue::{Asker, CommandQueue, QueueFull};
pub use rest::RestState;
pub use show::{ShowEvents, ShowLink, Source};
pub use tracker::TrackEvent;
