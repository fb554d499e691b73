//! Never-repeating idle motion: a fresh loop per axis whenever the last one
//! ends, joined to it as smoothly as a loop's interior.
//!
//! [`LoopStream`] generates each next [`LoopSet`] (each axis' LCG stream
//! goes on unbroken from loop to loop; a loop that does not keep pace with
//! the axis' last two, [`Paces`], is discarded), entered where it best
//! matches the outgoing loop; [`IdlePlayer`] plays the sets and blends each
//! join over [`JOIN`] with a smootherstep weight (a convex combination:
//! never outside either loop's range, velocity and acceleration
//! continuous). A set not ready in time lets the current one play once
//! more. [`IdleMode::FixedLoop`] replays set 0: the paper's behaviour.
//!
//! The method and its figures: the book's "Never-repeating idle"
//! (`docs/design/idle.md`).
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The idle stream”).

mod join;
mod pace;
mod source;
mod stream;
mod supply;

pub use crate::behaviour::IdleSource;
pub use join::{IdleError, IdleTiming, JOIN, MAX_JOIN_SAMPLES, join_weight};
pub use pace::{
    MAX_DRAWS, MAX_JOIN_TURN_RATIO, MAX_SPEED_RATIO, MAX_TURN_RATIO, Pace, Paces, Spread,
};
pub use source::{IdleMode, IdlePlayer, IdleStats};
pub use stream::{GenerateOnTake, LoopSet, LoopStream, MATCH_STRIDE, SetInfo, SetView, after_loop};
pub use supply::{LoopSupply, NoSupply};
