//! Idle-loop motion generation (Kocoń, section 3), computed once at boot.
//!
//! Per axis: the paper's LCG drives a ±δ random walk of N samples, a Hann window
//! of W taps smooths it, the result is scaled into [α1, α2] degrees, and the
//! loop is closed so that it starts at zero (the neutral pose) and repeats with
//! no jump. Two closures are available ([`Closure`]):
//!
//! - [`Closure::Seamless`] (default): the walk is made periodic (its mean step
//!   is removed) and smoothed *circularly*, so the loop is as smooth across its
//!   seam as everywhere else and equally lively along its whole length; it is
//!   then started at a crossing of the neutral pose.
//! - [`Closure::Paper`]: the paper's Figure 6 — causal smoothing, normalisation
//!   to exactly [α1, α2], a length-N Hann taper that brings both ends to zero,
//!   and an exchange of the two halves at a zero crossing drawn from the LCG.
//!
//! Everything is integer arithmetic, identical on host and target, with no
//! allocation; the smoother costs O(N) whatever W is (see `engine/mod.rs`).

mod config;
mod engine;
mod error;
mod kernel;
mod lcg;
mod limits;
mod storage;
mod trajectory;

pub use config::{AxisConfig, Closure, DEFAULT_HEAD, DEFAULT_N, DEFAULT_WINDOW_CAP, HeadConfig};
pub use engine::{LoopInfo, Trace};
pub use error::{AxisError, MotionError};
pub use kernel::HannKernel;
pub use lcg::{A as LCG_A, C as LCG_C, Lcg, step_of};
pub use limits::{MAX_N, MAX_STEP, MAX_WINDOW, MIN_N, MIN_WINDOW};
pub use storage::{FINE_PER_MDEG, Fnv1a, Integral16, LoopScale, Mdeg16, Sample};
pub use trajectory::{HeadTrajectories, Trajectory, generate_into};
