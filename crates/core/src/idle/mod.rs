//! Never-repeating idle motion: a fresh loop per axis whenever the last one
//! ends, joined to it as smoothly as a loop's interior.
//!
//! # The stream
//!
//! Set 0 is the configuration's own loops ([`LoopSet::generate`], the boot
//! loops, each entered at its neutral crossing). Set k+1 is generated with
//! the same configuration except the seeds: **each axis' next seed r(0) is
//! the last LCG value its previous loop drew**, r(N) (both closures draw
//! r(1)..r(N): the seamless one N walk steps, the paper's N − 1 steps and
//! its split). The LCG stream of an axis therefore goes on unbroken from
//! loop to loop, and the whole sequence follows from the three seeds of
//! the configuration ([`after_loop`] computes r(N) by squaring the LCG's
//! affine map). A loop the stream discards (below, "Keeping pace") is
//! skipped the same way: the next draw's seed is the last value the
//! discarded loop drew.
//!
//! # Keeping pace
//!
//! A stretch of frames around a join holds the end of one loop and the
//! start of the next. If one is lively and the other calm, the calm one
//! lowers the stretch's P95 and the lively one's fastest moments stand out
//! (max|d1|/P95|d1| reached 3.13 while every loop alone stays below 2.75),
//! and a join between loops that match badly can turn sharply. A stretch of
//! two loop lengths holds two loops whole and the ends of the loops either
//! side, so loops two apart meet in one P95 too. So each axis draws its next loop until
//! it keeps pace with the axis' last two loops ([`Paces`]), measured on the
//! loops' samples in m° ([`Pace`], cyclic, per sample):
//!
//! - against each of the last two loops, the largest |d1| of either loop is
//!   at most [`MAX_SPEED_RATIO`] (2) times the other's P95|d1|, and the
//!   largest |d2| at most [`MAX_TURN_RATIO`] (2.25) times the other's
//!   P95|d2|;
//! - the largest |d2| over the join into the last loop is at most
//!   [`MAX_JOIN_TURN_RATIO`] (2.75) times the new loop's P95|d2|;
//! - once entered and blended, the largest |d2| over the new join's samples
//!   is at most [`MAX_JOIN_TURN_RATIO`] times the smallest P95|d2| of the
//!   new loop and the last two.
//!
//! Each loop is thus measured against the loops up to two away, and each
//! join against the two loops before it, the one it enters and the one
//! after it.
//! A loop that breaks a bound is discarded and the axis draws the next
//! one, from the seed after it; after [`MAX_DRAWS`] (16) draws the one
//! closest to the bounds is kept (generated again from its seed; the
//! stream goes on after the last draw). The bounds are tighter than the
//! frames' 3 because the samples do not see all the frames do (the spline
//! between samples, the m° rounding of each frame, a stretch holding only
//! part of each loop). A loop's own interior is never judged, only the
//! difference between loops: "as smooth as a loop's interior". Set 0
//! is the configuration's own and never discarded; set 1 is measured
//! against it as both of the last two loops.
//!
//! Over 1,000 seeds × 50 joins × 3 axes (the host test `idle_stream`),
//! 43 % of the loops drawn are discarded (36 % with neighbours only), a
//! set draws 2.26 loops more on average, at most 15 are discarded for one
//! loop and 127 loops in 153,000 take all 16 draws. The design and its
//! reasons are in the book's "Never-repeating idle" (`docs/design/idle.md`);
//! what a set costs in the background, on its measured figures page.
//!
//! # The join
//!
//! Every loop is played once through, N samples in `L` (30 s at the
//! defaults: 1500 frames at 50 Hz), and its first and last `J` ([`JOIN`],
//! 2 s) overlap the loops before and after it: over a join the outgoing
//! loop plays its last `J`, the incoming loop its first `J`, and the
//! frame at `t` into the join shows
//!
//! ```text
//! out + s(t/J)·(in − out),   s(u) = 10u³ − 15u⁴ + 6u⁵,   0 ≤ t < J
//! ```
//!
//! (blended on the samples the join covers, and interpolated between them
//! as any sample is: all in time, so the frame rate changes nothing)
//!
//! a convex combination (the angle stays inside both loops' ranges, so
//! inside [α1, α2]) whose weight has zero first and second derivatives at
//! both ends, so velocity and acceleration stay continuous. Joins come
//! every `L − J` (28 s). No sample of a loop is played
//! twice, so no part of a loop returns at the next join.
//!
//! The blend has little to hide because the incoming loop is entered where
//! it already resembles the outgoing one: each loop is a ring (seamless, so
//! it can be entered at any sample), and the generator chooses the entry s
//! that minimises the squared difference between the incoming loop's samples
//! s, s+3, …, s+J and the outgoing loop's exit (its samples over the join,
//! `J·N/L` = 60 at the defaults), which matches value, slope and curvature
//! together ([`SetInfo::mismatch`] reports what is left). Only set 0 starts
//! at the neutral pose.
//!
//! # Generation and hand-over
//!
//! [`LoopStream`] generates each set (the loops, their pace and the entry
//! search: a few million instructions on a Cortex-M0+, measured by the QEMU
//! smoke run and shown on the book's measured figures page) into a
//! [`LoopSet`] buffer;
//! [`IdlePlayer`] plays the sets frame by frame and takes the next one
//! through a [`LoopSupply`] at the first frame its join is due. The firmware
//! generates in a low-priority task and passes `&'static mut` buffers
//! through channels (`frame_task`); the host calls the generator on the
//! spot. Both play the same frames. Should a set not be ready in time, the
//! current one plays once more (it is seamless) and the join is tried a
//! loop later, on the same samples.
//!
//! # The fixed loop
//!
//! [`IdleMode::FixedLoop`] plays set 0 for ever: the paper's behaviour,
//! one loop per axis replayed every `L`.

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
