//! Frame playback: which point of the loop a frame shows.
//!
//! The position of frame `k` is `k · frame_period mod loop_duration` in
//! exact integer arithmetic (no drift); between samples the loop is
//! interpolated with a cyclic Catmull-Rom spline, continuous in value and
//! velocity across the seam too, in `i32` (larger steps in `i64`).
//!
//! ```
//! use idle_head_core::playback::{LoopSource, Playback};
//! use idle_head_core::{Angle, Microseconds, Millis};
//!
//! let ramp: [Angle; 4] = [0, 1000, 2000, 1000].map(Angle::from_millidegrees);
//! // 4 samples over 160 ms, 20 ms frames: two frames per sample.
//! let p = Playback::new(Millis(160), Microseconds(20_000), 4).unwrap();
//! let at = |k| p.offsets(k, [&ramp, &ramp, &ramp])[0].millidegrees();
//! assert_eq!(at(0), 0);
//! assert_eq!(at(2), 1000); // on sample 1
//! assert_eq!(at(3), 1625); // between samples 1 and 2 (linear would give 1500)
//! assert_eq!(at(8), 0); // one loop later: back to the start
//! ```
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Playback”).

mod player;
mod timing;

pub use player::{Axes, Cursor, Player};
pub use timing::{LoopSource, Playback, PlaybackError};
