//! The integer pipeline: walk → Hann smoothing → scaling → loop closure.
//!
//! The smoothing works on the walk's steps with sliding sums over absolute
//! time (O(N), independent of W, exact integers: no drift), and the
//! integral of the quantised velocity is exact at every sample
//! ([`Quantiser`]). No scratch memory beyond the output buffer and the
//! W-tap ring; every intermediate fits `i32`.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The integer pipeline”).
#![allow(clippy::many_single_char_names)] // the notation of the derivation above

mod paper;
mod scale;
mod seamless;
mod sweep;

pub(super) use scale::finalise;

use super::kernel::HannKernel;
use super::storage::{LoopScale, Sample};
use super::{AxisConfig, Closure, MotionError};

/// What the engine decided for one loop.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopInfo {
    /// The index, in generation order, of the sample of the smoothed, scaled
    /// loop where playback starts (the split point p of the paper's Figure 6).
    pub split: u16,
    /// Where playback starts in the stored buffer: the loop is kept as a ring
    /// (exchanging the two halves is a matter of where reading starts).
    pub start: u16,
    /// How many zero crossings were candidates for the split.
    pub crossings: u16,
    /// Up-steps (+δ) among the walk's steps.
    pub up_steps: u16,
}

/// Observer of intermediate stages, for previews and tests.
///
/// All methods default to doing nothing; `()` implements it as a no-op that
/// compiles away.
pub trait Trace {
    /// Whether the observer wants the stages at all (`()` does not: the
    /// engine then skips the work of rebuilding them).
    const ENABLED: bool = true;

    /// The smoothed walk before scaling, at loop index `n` (generation order),
    /// in units of the walk step δ (up to an additive constant).
    fn smoothed(&mut self, _n: usize, _walk_steps: f32) {}
    /// The scaled loop before closure at index `n` (generation order), in fine
    /// units of 1/256 millidegree.
    fn normalized(&mut self, _n: usize, _fine: i32) {}
}

impl Trace for () {
    const ENABLED: bool = false;
}

/// Runs the pipeline for one axis into `out` (length N, validated by the
/// caller); the samples map to angles with the returned scale.
pub(super) fn generate<S: Sample, T: Trace, const CAP: usize>(
    out: &mut [S],
    cfg: &AxisConfig,
    kernel: &HannKernel<CAP>,
    trace: &mut T,
) -> Result<(LoopInfo, LoopScale), MotionError> {
    if kernel.window() != cfg.window || out.len() < 2 * usize::from(cfg.window) {
        // Callers validate first; this keeps the function total on its own.
        return Err(MotionError::WindowTooLarge {
            window: cfg.window,
            max: (out.len() / 2) as u16,
        });
    }
    match cfg.closure {
        Closure::Seamless => seamless::seamless(out, cfg, kernel, trace),
        Closure::Paper => paper::paper(out, cfg, kernel, trace),
    }
}

/// What both closures read off the buffer, the configuration and the kernel.
#[derive(Clone, Copy)]
pub(super) struct Basics<'k> {
    /// N, the loop's length.
    n: usize,
    /// W, the window's length.
    w: usize,
    /// The kernel table, W entries.
    table: &'k [(i16, i16)],
    /// The table scale Q (the paper's closure only).
    q: i32,
    /// Q².
    qq: i32,
}

impl<'k> Basics<'k> {
    fn of<S, const CAP: usize>(out: &[S], cfg: &AxisConfig, kernel: &'k HannKernel<CAP>) -> Self {
        let q = kernel.scale();
        Self {
            n: out.len(),
            w: usize::from(cfg.window),
            table: kernel.table(),
            q,
            qq: q * q,
        }
    }
}

/// Error-feedback quantisation by 2^shift (0 ≤ shift ≤ 30): after each
/// push, the outputs so far sum to exactly ⌊(r₀ + the inputs so far)/2^shift⌋,
/// r₀ the starting residue, so an integral of the outputs never drifts from
/// the exact one.
///
/// The paper's closure quantises with it; the seamless one does the same
/// inside its sweep.
#[derive(Clone, Copy)]
pub(super) struct Quantiser {
    /// The inputs' sum so far, modulo 2^shift.
    residue: i32,
    shift: u32,
}

impl Quantiser {
    /// A quantiser by 2^`shift` with nothing carried over.
    pub(super) const fn new(shift: u32) -> Self {
        Self::with_residue(shift, 0)
    }

    /// A quantiser by 2^`shift` that carries `residue` (< 2^shift) over.
    pub(super) const fn with_residue(shift: u32, residue: i32) -> Self {
        Self { residue, shift }
    }

    /// Quantises the next input.
    pub(super) fn push(&mut self, v: i32) -> i32 {
        let total = v + self.residue;
        self.residue = total & ((1 << self.shift) - 1);
        total >> self.shift
    }
}
