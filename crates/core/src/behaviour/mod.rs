//! Behaviour: gestures and gaze layered over the idle motion.
//!
//! ```text
//!  console, scripts ──try_submit──▶ CommandQueue ──drain (≤ 2 a frame)──┐
//!                                                                       ▼
//!  IdleSource ──idle offsets──▶ Mixer (gaze + idle·gain·duck + gestures) ──▶ Show ──▶ FrameDriver
//!                                   └── limit mode per axis (idle | gesture)   (DMX, Bottango)
//! ```
//!
//! - [`gesture`], [`shape`]: gestures as they play; [`gaze`]: `look` and
//!   `center`; [`rest`]: rest and wake; [`show`]: DMX and Bottango.
//! - [`mixer`]: where the layers meet, and the limit mode per axis (an
//!   example on [`Mixer`]); [`head`]: the frame engine; [`queue`]: the
//!   command queue.
//! - [`config`]: [`BehaviourConfig`] in physical units, validated into
//!   [`BehaviourParams`] ([`params`]).
//!
//! Gaze and idle changes glide from the current position, velocity and
//! acceleration, gestures come in along C2 envelopes: nothing jumps. The frame path is integer
//! arithmetic with 32-bit multiplies only (Q16 fractions, millidegrees).
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Behaviour”).

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
