//! The integer pipeline: walk → Hann smoothing → scaling → loop closure.
//!
//! # Smoothing in O(N), independent of W
//!
//! Smoothing the walk u with the Hann kernel h equals smoothing its steps
//! e(k) = u(k) − u(k−1) ∈ {−1, 0, +1} and integrating, because convolution
//! commutes with summation. With h(m) = ½ − ½·cos(ωm), ω = 2π/W, the smoothed
//! velocity at n is
//!
//! ```text
//! v(n) = Σₘ h(m)·e(n−m) = ½·B(n) − ½·Σₖ e(k)·cos(ω(n−k))          (k over the window)
//!      = ½·B(n) − ½·[cos ωn · Σₖ e(k) cos ωk  +  sin ωn · Σₖ e(k) sin ωk]
//! ```
//!
//! where B(n) is the plain window sum. B and the two phasor sums P꜀, Pₛ are
//! *sliding sums over absolute time*: when the window moves by one sample the
//! entering and the leaving step share the same residue n mod W, so each sum
//! changes by (`e_new` − `e_old`)·T[n mod W] — one table entry, no rotation, no
//! rounding. The sums are therefore exact integers at every n: there is no
//! drift to re-anchor. Only the table rounding (≈ 1/Q per tap) separates the
//! result from the real-valued Hann smoothing; `host-tests` measures it against
//! a direct-form f64 convolution.
//!
//! # What the buffer holds
//!
//! The smoothed velocity V is quantised to a step 2^shift by an
//! error-feedback quantiser, so the integral X of the quantised velocity
//! equals ⌊(exact integral)/2^shift⌋ at every sample: no drift.
//!
//! - Seamless closure: the buffer receives X itself, wrapping in 16 bits,
//!   with a step ([`raw_shift`]) that makes a typical loop span 2¹⁵..2¹⁶
//!   units (a wider one is quantised again); a [`LoopScale`] maps it to
//!   angles about the loop's start. [`Q16`](super::Q16) storage keeps it as
//!   it is: no pass after the sweep touches every sample.
//! - Paper closure (taper and split need the angles): the buffer holds the
//!   *second difference* ΔΔX as `i16` (see [`x_shift`]) and a scaling pass
//!   integrates it twice into angles.
//!
//! No scratch memory beyond the output buffer and the W-tap ring.
//!
//! # Magnitudes (all fit `i32`)
//!
//! With table scale Q (Q²·W < 2²⁹) and bits b ∈ {0,1} of the steps:
//! - `Pb = Σ b(k)·T[k mod W]` is a 2-vector of length ≤ W·(Q+1);
//! - `cp = T꜀[j]·Pb꜀ + Tₛ[j]·Pbₛ` ≤ (Q+1)²·W (Cauchy–Schwarz) < 2²⁹·(1 + 3/Q);
//! - `V = Q²·Bb − cp` = 2Q²·Σ h·b ∈ [0, Q²W] up to rounding, |V| < 2³⁰;
//! - `V − q` with the detrend q ≤ Q²W, plus the quantiser's residue: < 2³¹;
//! - ΔX = (V − q)/2^shift with 2^shift ≥ 2N, so |X| < 2³⁰ over the loop;
//! - seamless: 2^shift ≥ 2¹⁵, so |ΔX| < 2¹⁵ and neighbouring samples differ
//!   by an exact `i16`; the scale multiplies offsets < 2¹⁶ by m < 2¹⁵;
//! - paper: |ΔΔX| < 2¹⁴ (see [`x_shift`]), stored as `i16`; the scaling pass
//!   forms ΔX·m with m sized by the largest |ΔX|: < 2³¹.
//!
//! # Closing the seamless loop exactly
//!
//! The detrend q is the loop's total Σ V divided by N. The zero-sum table makes
//! that total Q²·W·(up steps) exactly, except for the windows that wrap around
//! the loop's end, whose steps are seen at table phases shifted by N mod W;
//! [`initial_window`] computes their share E exactly in O(W). With q =
//! ⌊(Q²·W·ups − E)/N⌋ the remainder is below N < 2^shift, so the quantised
//! integral returns exactly to its start.

#![allow(clippy::many_single_char_names)] // the notation of the derivation above

use super::kernel::{HannKernel, MAX_WINDOW};
use super::lcg::Lcg;
use super::storage::{FINE_PER_MDEG, LoopScale, Sample};
use super::{AxisConfig, Closure, MotionError};

/// Smallest extent of the smoothed integral (in `X` units) that is scaled;
/// below it the walk is treated as flat ([`MotionError::Degenerate`]).
const MIN_EXTENT: i64 = 64;

/// The quantisation step `2^shift` from `V` units to the stored integral `X`.
///
/// The pipeline stores the *second difference* of X (|ΔΔX| is small: the
/// smoothed walk's acceleration), which buys 4 to 6 bits over storing its
/// velocity. The step must keep
/// - |ΔΔX| ≤ |ΔV|/2^shift + 2 < 2¹⁴, with |ΔV| ≤ 2Q² (the Hann kernel rises
///   from 0 to 1 and back, so its total variation is 2) plus the table
///   rounding, at most 8·(Q+1)·W, plus a margin of Q²;
/// - 2^shift ≥ 2N, which bounds |X| < 2³¹ and makes the seamless loop's
///   detrend residue (< N) vanish in the floor: the loop closes exactly.
fn x_shift(q: i32, w: usize, n: usize) -> u32 {
    let dv_bound = 3 * i64::from(q) * i64::from(q) + 8 * i64::from(q + 1) * w as i64;
    let by_acc = 64 - ((dv_bound >> 13) as u64).leading_zeros();
    let by_len = 64 - ((2 * n as u64 - 1).leading_zeros());
    by_acc.max(by_len)
}

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
pub(super) fn generate<S: Sample, T: Trace>(
    out: &mut [S],
    cfg: &AxisConfig,
    kernel: &HannKernel,
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
        Closure::Seamless => seamless(out, cfg, kernel, trace),
        Closure::Paper => paper(out, cfg, kernel, trace),
    }
}

/// Running extent of the smoothed integral.
#[derive(Clone, Copy)]
struct Extent {
    min: i32,
    max: i32,
}

impl Extent {
    const fn new(v: i32) -> Self {
        Self { min: v, max: v }
    }
    #[inline]
    fn add(&mut self, v: i32) {
        if v < self.min {
            self.min = v;
        }
        if v > self.max {
            self.max = v;
        }
    }
}

/// Error-feedback quantiser from `V` units to the integral's increments `Vq`:
/// after each push, Σ Vq = ⌊Σ v / 2^shift⌋ exactly (see the module docs).
#[derive(Clone, Copy)]
struct Quantiser {
    residue: i32,
    shift: u32,
    mask: i32,
}

impl Quantiser {
    const fn new(shift: u32) -> Self {
        Self {
            residue: 0,
            shift,
            mask: (1 << shift) - 1,
        }
    }
    #[inline]
    fn push(&mut self, v: i32) -> i32 {
        let r = v + self.residue;
        self.residue = r & self.mask;
        r >> self.shift
    }
}

// ---------------------------------------------------------------------------
// Seamless closure: periodic walk, circular smoothing, start at a crossing.
// ---------------------------------------------------------------------------

/// What both closures read off the buffer, the configuration and the kernel.
struct Basics<'k> {
    /// N, the loop's length.
    n: usize,
    /// W, the window's length.
    w: usize,
    /// The kernel table, W entries.
    table: &'k [(i16, i16)],
    /// The table scale Q.
    q: i32,
    /// Q².
    qq: i32,
}

impl<'k> Basics<'k> {
    fn of<S>(out: &[S], cfg: &AxisConfig, kernel: &'k HannKernel) -> Self {
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

/// The seamless loop.
///
/// The circular step sequence is e(k) = ±1 from r(k+1), k = 0..N−1. Removing
/// its mean step D/N makes the walk periodic; the detrend is applied to the
/// smoothed velocity, where it is the constant q = Q²·W·(up steps)/N. The
/// window for output n covers k = n−W+1..n taken modulo N.
///
/// The buffer receives the quantised integral X itself (wrapping `i16`, see
/// [`raw_shift`]); the returned [`LoopScale`] maps it to angles about the
/// loop's start.
#[allow(clippy::too_many_lines)] // one pass after another, each commented
fn seamless<S: Sample, T: Trace>(
    out: &mut [S],
    cfg: &AxisConfig,
    kernel: &HannKernel,
    trace: &mut T,
) -> Result<(LoopInfo, LoopScale), MotionError> {
    let Basics {
        n, w, table, qq, ..
    } = Basics::of(out, cfg, kernel);
    let shift = raw_shift(qq, w, n);

    // Pass 1: count the up-steps of the whole circular walk.
    let ones = count_ups(cfg.seed, n);
    // Initial window: k = 0..W−1, output index W−1. The same steps give the
    // wrap correction E (see `initial_window`) and fill the tap ring.
    let mut main = Lcg::new(cfg.seed);
    // A heapless vector: stack storage (16 B a tap, 8 KiB at most) without
    // clearing all of it per axis.
    let mut ring: heapless::Vec<Tap, { MAX_WINDOW as usize }> = heapless::Vec::new();
    // N mod W, the one division of the sweep's indices (software on ARMv6-M).
    let n_mod_w = n % w;
    let (pc, ps, bb, wrap_sum) = initial_window(table, n_mod_w, &mut main, qq, &mut ring);
    let taps = ring.as_mut_slice();
    let detrend = detrend(qq * w as i32, ones, wrap_sum, n);

    // Pass 2: slide the window around the loop, storing X in generation
    // order: out[t] belongs to loop index (W−1+t) mod N.
    let mut sweep = Sweep {
        pc,
        ps,
        acc: bb - detrend,
        residue: 0,
        x: 0,
        rising: true,
        lo: 0,
        hi: 0,
    };
    // The first output, n = W−1, at residue W−1.
    let (tc, ts) = table[w - 1];
    let r = sweep.acc - (i32::from(tc) * pc + i32::from(ts) * ps);
    let x_first = r >> shift;
    (sweep.residue, sweep.x, sweep.rising) = (r - (x_first << shift), x_first, x_first >= 0);
    (sweep.lo, sweep.hi) = (x_first, x_first);
    if let Some(o) = out.first_mut() {
        *o = S::from_scratch(x_first as i16);
    }
    // Slides s = 1..N−1: step W−1+s enters, step s−1 leaves, both at residue
    // (s−1) mod W. When the entering index reaches N (s = N−W+1) the circular
    // walk wraps to e(0).
    let wrap_at = n - w + 1;
    let (head, tail) = out.split_at_mut(wrap_at);
    sweep.run(&mut head[1..], taps, 0, &mut main, qq, shift);
    let mut again = Lcg::new(cfg.seed);
    // The tail's first residue: (wrap_at − 1) mod W = (N − W) mod W = N mod W.
    sweep.run(tail, taps, n_mod_w, &mut again, qq, shift);
    sweep.settle();
    debug_assert_eq!(sweep.x, 0, "the seamless loop closes exactly");
    let (mut lo, mut hi) = (sweep.lo, sweep.hi);
    // X spans at most 65535 raw units, so that its offsets from the lowest
    // sample are exact in `u16`; a wider loop than `raw_shift` expects is
    // quantised again.
    let mut step_log = shift;
    if hi - lo > i32::from(u16::MAX) {
        let k = requantise(out, x_first, lo, hi);
        (lo, hi, step_log) = (lo >> k, hi >> k, shift + k);
    }
    let low = lo as i16;
    let offset = |s: &S| i32::from(s.to_scratch().wrapping_sub(low) as u16);
    if T::ENABLED {
        // X along the loop, for the observer (previews only).
        let scale = trace_scale(step_log, qq, w) * 2.0;
        for (t, o) in out.iter().enumerate() {
            trace.smoothed((w - 1 + t) % n, (lo + offset(o)) as f32 * scale);
        }
    }
    let a1 = i64::from(cfg.range.min.millidegrees()) * i64::from(FINE_PER_MDEG);
    let a2 = i64::from(cfg.range.max.millidegrees()) * i64::from(FINE_PER_MDEG);
    // The level that the range's zero maps to under the paper's
    // normalisation, as an offset from the lowest sample.
    let span = hi - lo;
    let level = (-a1 * i64::from(span)) / (a2 - a1);

    // A sample, in generation order, where the loop crosses that level:
    // playback starts there (the stored order stays a ring).
    let (start, pivot) = find_crossing(out, low, level as i32);
    // As a loop index: (start + W − 1) mod N, with start + W − 1 < 2N.
    let split = match start + w - 1 {
        i if i >= n => i - n,
        i => i,
    };

    // Scale about the pivot so that it maps to exactly 0 and both extremes
    // stay inside [α1, α2]; the tighter side reaches its bound (less one
    // fine unit: the offset's floor may add one).
    let up = i64::from(span - pivot);
    let down = i64::from(pivot);
    let (num, den) = if down == 0 || (up != 0 && a2 * down <= -a1 * up) {
        (a2 - 1, up)
    } else {
        (-a1 - 1, down)
    };
    // Offsets from the lowest sample are below 2¹⁶.
    let (m, mshift) =
        multiplier(num, den, 1 << 16).ok_or(MotionError::Degenerate { seed: cfg.seed })?;
    let scale = LoopScale {
        low,
        m,
        shift: mshift as u8,
        offset: (pivot * m) >> mshift,
    };
    if T::ENABLED {
        for (t, o) in out.iter().enumerate() {
            trace.normalized((t + w - 1) % n, scale.fine(o.to_scratch()));
        }
    }
    let info = LoopInfo {
        split: split as u16,
        start: start as u16,
        crossings: 1,
        up_steps: ones as u16,
    };
    Ok((info, scale))
}

/// The detrend q = ⌊(Q²·W·ups − E)/N⌋ (see the module docs), with
/// `qqw` = Q²·W < 2²⁹, `ups` ≤ N ≤ 8192 and |E| < 2²⁴: in 32-bit steps
/// (two divisions, not a 64-bit one). With Q²·W = a·N + b, b < N, the
/// quotient is a·ups + ⌊(b·ups − E)/N⌋, where |b·ups − E| < 2²⁶ + 2²⁴.
fn detrend(qqw: i32, ups: u32, e: i32, n: usize) -> i32 {
    let (qqw, n) = (qqw as u32, n as u32);
    let a = qqw / n;
    let b = qqw - a * n;
    let y = (b * ups) as i32 - e;
    let rest = if y >= 0 {
        (y as u32 / n) as i32
    } else {
        -(((-y - 1) as u32 / n) as i32) - 1
    };
    (a * ups) as i32 + rest
}

/// The quantisation step `2^shift` from `V` units to the stored integral X.
///
/// X is stored as `i16`, so its extent should stay below 2¹⁵ and use as much
/// of it as it can. The smoothed integral is Q²·W/2 times the smoothed
/// detrended walk (in steps δ), whose extent is about 0.9·√N for a typical
/// seed (0.14 to 2.1·√N over many); with the step chosen so that a typical
/// extent lands in 2¹⁵/3..2¹⁵·2/3, a loop needs quantising again
/// ([`requantise`]) only in the upper tail. The step is at least 2¹⁵, which
/// keeps each sample's |ΔX| below 2¹⁵ (|V − q| < 2³⁰), so differences of
/// stored samples are exact in `i16`, and at least 2N, which makes the
/// detrend's residue (< N) vanish in the floor: the loop closes exactly.
fn raw_shift(qq: i32, w: usize, n: usize) -> u32 {
    // Q²·W/2 · 0.9·√N · 3/2 ≈ Q²·W·√N·0.675 = ⌊y/40⌋, y = Q²·W·√N·27;
    // Q²·W < 2²⁹ and 27·√N < 2²¹ each fit u32, their product u64.
    let y = u64::from(qq as u32 * w as u32) * u64::from(27 * (n as u32).isqrt());
    let by_extent = bit_len_div40(y).saturating_sub(16);
    let by_len = 64 - ((2 * n as u64 - 1).leading_zeros());
    by_extent.max(by_len).max(15)
}

/// The bit length of ⌊y/40⌋, without a (software) 64-bit division.
///
/// With L the bit length of y, 2^(L−1) ≤ y < 2^L, so ⌊y/40⌋ lies in
/// [2^(L−6)·0.8, 2^(L−6)·1.6): its bit length is L−5 where y ≥ 40·2^(L−6),
/// else L−6 (and y ≥ 40·2^(L−6) exactly where ⌊y/2^(L−6)⌋ ≥ 40).
fn bit_len_div40(y: u64) -> u32 {
    let len = 64 - y.leading_zeros();
    if len < 6 {
        return 0; // y < 32 < 40
    }
    if y >> (len - 6) >= 40 {
        len - 5
    } else {
        len - 6
    }
}

/// Pass 1: the number of up-steps among the first `n` steps of the walk.
#[inline(never)]
fn count_ups(seed: u32, n: usize) -> u32 {
    let mut r = seed;
    let mut ones: u32 = 0;
    let mut next = || {
        r = r.wrapping_mul(super::lcg::A).wrapping_add(super::lcg::C);
        r >> 31
    };
    // Four steps a turn: the loop's own count and branch cost a quarter.
    for _ in 0..n / 4 {
        ones += next() + next() + next() + next();
    }
    for _ in 0..n % 4 {
        ones += next();
    }
    ones
}

/// Quantises the stored X again by the smallest 2^k that brings its extent
/// [`lo`, `hi`] within 65535 units: X' = ⌊X/2^k⌋, exactly, for every sample
/// (consecutive samples differ by less than 2¹⁵, so the ring unwraps from
/// `x0`, the value of `out[0]`). Returns k.
#[cold]
fn requantise<S: Sample>(out: &mut [S], x0: i32, lo: i32, hi: i32) -> u32 {
    let mut k = 1;
    while (hi >> k) - (lo >> k) > i32::from(u16::MAX) {
        k += 1;
    }
    let (mut x, mut prev) = (x0, x0 as i16);
    for o in out.iter_mut() {
        let raw = o.to_scratch();
        x += i32::from(raw.wrapping_sub(prev));
        prev = raw;
        *o = S::from_scratch((x >> k) as i16);
    }
    k
}

/// One tap of the sliding window (16 bytes): the kernel table entry of its
/// residue j and the step currently in the window at that residue (0 for
/// down, −1 for up). The step leaving the window and the one entering it
/// share the residue, so this ring replaces a second, lagging generator.
#[derive(Clone, Copy)]
struct Tap {
    /// Q·cos, widened: one load and no sign extension on ARMv6-M.
    c: i32,
    /// Q·sin, widened.
    s: i32,
    up: i32,
    /// Scratch: the velocity V − q of the tap's latest sample.
    v: i32,
}

impl Tap {
    /// No table entry, no step.
    const EMPTY: Self = Self {
        c: 0,
        s: 0,
        up: 0,
        v: 0,
    };

    /// The table entry (Q·cos, Q·sin).
    #[inline]
    fn parts(&self) -> (i32, i32) {
        (self.c, self.s)
    }
}

/// The state of the circular sweep (pass 2): the sliding sums, the
/// quantiser and X with its extremes, tracked only where its slope changes
/// sign (a few times per smoothing length).
#[derive(Clone, Copy)]
struct Sweep {
    pc: i32,
    ps: i32,
    /// Q²·Bb − q: the window's up-steps times Q², minus the detrend.
    acc: i32,
    residue: i32,
    /// X after the last sample.
    x: i32,
    /// Whether ΔX of the last sample was ≥ 0.
    rising: bool,
    lo: i32,
    hi: i32,
}

impl Sweep {
    /// Slides over `out.len()` samples, the first at residue `j`, with the
    /// entering steps drawn from `main`; stores X.
    fn run<S: Sample>(
        &mut self,
        out: &mut [S],
        taps: &mut [Tap],
        mut j: usize,
        main: &mut Lcg,
        qq: i32,
        shift: u32,
    ) {
        let mut rest = out;
        let mut r = main.value();
        while !rest.is_empty() {
            let ring = taps.get_mut(j..).unwrap_or_default();
            let take = ring.len().min(rest.len());
            let (now, later) = rest.split_at_mut(take);
            let ring = ring.get_mut(..take).unwrap_or_default();
            r = self.stretch(now, ring, r, qq, shift);
            rest = later;
            j = 0;
        }
        *main = Lcg::new(r);
    }

    /// One stretch of taps: slides the window ([`Sweep::slide`]), then
    /// quantises V − q, advances X and stores it ([`Sweep::store`]).
    fn stretch<S: Sample>(
        &mut self,
        out: &mut [S],
        ring: &mut [Tap],
        r: u32,
        qq: i32,
        shift: u32,
    ) -> u32 {
        let r = self.slide(ring, r, qq);
        // The step as an immediate where `raw_shift` usually lands (the mask
        // and shift then take no registers in the loop); any other step runs
        // the same loop with it in a register.
        match shift {
            17 => self.store::<S, 17>(out, ring, shift),
            18 => self.store::<S, 18>(out, ring, shift),
            19 => self.store::<S, 19>(out, ring, shift),
            _ => self.store::<S, 0>(out, ring, shift),
        }
        r
    }

    /// Slides the window over `ring`, leaving each sample's V − q in its tap.
    #[inline(never)]
    fn slide(&mut self, ring: &mut [Tap], mut r: u32, qq: i32) -> u32 {
        let (mut pc, mut ps, mut acc) = (self.pc, self.ps, self.acc);
        let mut one = |tap: &mut Tap, r: &mut u32| {
            *r = r.wrapping_mul(super::lcg::A).wrapping_add(super::lcg::C);
            let enter = *r as i32 >> 31;
            let (tc, ts) = tap.parts();
            if enter != tap.up {
                tap.up = enter;
                if enter != 0 {
                    // An up-step enters, a down-step leaves.
                    pc += tc;
                    ps += ts;
                    acc += qq;
                } else {
                    pc -= tc;
                    ps -= ts;
                    acc -= qq;
                }
            }
            tap.v = acc - (tc * pc + ts * ps);
        };
        // Four taps a turn: the loop's spills and branch are paid once per four.
        let mut pairs = ring.chunks_exact_mut(4);
        for pair in &mut pairs {
            if let [a, b, c, e] = pair {
                one(a, &mut r);
                one(b, &mut r);
                one(c, &mut r);
                one(e, &mut r);
            }
        }
        for tap in pairs.into_remainder() {
            one(tap, &mut r);
        }
        (self.pc, self.ps, self.acc) = (pc, ps, acc);
        r
    }

    /// Quantises the velocities in `ring`, advances X and stores it in
    /// `out`. Two loops, one while X rises and one while it falls, so that
    /// the slope's sign is where the code is, not a register.
    ///
    /// The step is `2^SHIFT`, a constant, or `2^shift` with `SHIFT = 0`
    /// (`raw_shift` is at least 15, so 0 never is a step).
    #[inline(never)]
    fn store<S: Sample, const SHIFT: u32>(&mut self, out: &mut [S], ring: &[Tap], shift: u32) {
        let shift = if SHIFT == 0 { shift } else { SHIFT };
        // The residue v mod 2^shift is carried in the top bits of a word
        // (`low`): no mask to hold in a register.
        let up = 32 - shift;
        let (mut low, mut x) = ((self.residue as u32) << up, self.x);
        let mut rising = self.rising;
        let len = out.len().min(ring.len());
        let (out, ring) = (&mut out[..len], &ring[..len]);
        let mut i = 0;
        while i < len {
            if rising {
                while i < len {
                    let v = ring[i].v + (low >> up) as i32;
                    low = (v as u32) << up;
                    let v = v >> shift;
                    if v < 0 {
                        // X (before this sample) is a local maximum.
                        self.hi = self.hi.max(x);
                        x += v;
                        out[i] = S::from_scratch(x as i16);
                        i += 1;
                        rising = false;
                        break;
                    }
                    x += v;
                    out[i] = S::from_scratch(x as i16);
                    i += 1;
                }
            } else {
                while i < len {
                    let v = ring[i].v + (low >> up) as i32;
                    low = (v as u32) << up;
                    let v = v >> shift;
                    if v >= 0 {
                        // X (before this sample) is a local minimum.
                        self.lo = self.lo.min(x);
                        x += v;
                        out[i] = S::from_scratch(x as i16);
                        i += 1;
                        rising = true;
                        break;
                    }
                    x += v;
                    out[i] = S::from_scratch(x as i16);
                    i += 1;
                }
            }
        }
        let residue = (low >> up) as i32;
        (self.residue, self.x, self.rising) = (residue, x, rising);
    }

    /// Includes the current X in the extremes (the sweep's end).
    fn settle(&mut self) {
        self.lo = self.lo.min(self.x);
        self.hi = self.hi.max(self.x);
    }
}

/// Fills the tap ring with the initial window (steps k = 0..W−1, drawn from
/// `main`) and returns its sums Pb꜀, Pbₛ, Q²·Bb and the wrap correction E
/// (`n_mod_w` is N mod W).
///
/// ## The wrap correction E
///
/// The part of Σₙ cp(n) that the zero-sum table does not cancel.
///
/// Over the circular sweep (outputs n = W−1..N+W−2) each absolute step index
/// k contributes b(k)·T[k]·Σ_{n∋k} T[n]. Steps k = W−1..N−1 are in W
/// consecutive windows, a full period of the table: zero. The first W−1
/// steps appear twice, as k and k+N, each in part of its windows; with an
/// exact cosine the two parts would again form one full period, but the
/// table's rounding at the two phases differs. E collects exactly that:
///
/// ```text
/// E = Σ_{k<W−1} b(k)·( T[k]·SA(k) + T[(k+N) mod W]·SB(k) )
/// SA(k) = Σ_{n=W−1}^{k+W−1} T[n mod W],  SB(k) = Σ_{n=k+N}^{N+W−2} T[n mod W]
/// ```
///
/// (products of 2-vectors are dot products). Each step's two parts cover
/// the W lags 0..W−1 once, so its term is a sum of W rounding errors of the
/// table's products, and |E| stays far inside `i32`: below 2²⁴ for every
/// W ≤ 511 and every N mod W, whatever the steps (`host-tests` checks all
/// of them). The partial sums may leave `i32`, so they wrap: the final sum
/// is exact. O(W), once per axis.
///
/// [`initial_window`] sums it while it fills the window.
#[inline(never)] // a function of its own: registers of its own
fn initial_window(
    table: &[(i16, i16)],
    n_mod_w: usize,
    main: &mut Lcg,
    qq: i32,
    ring: &mut heapless::Vec<Tap, { MAX_WINDOW as usize }>,
) -> (i32, i32, i32, i32) {
    let w = table.len();
    // The window's steps, one tap each. Cannot fail: the table has at most
    // MAX_WINDOW entries.
    let _ = ring.resize(w, Tap::EMPTY);
    let mut r = main.value();
    for (tap, &e) in ring.iter_mut().zip(table) {
        r = r.wrapping_mul(super::lcg::A).wrapping_add(super::lcg::C);
        (tap.c, tap.s) = (i32::from(e.0), i32::from(e.1));
        tap.up = r as i32 >> 31;
    }
    *main = Lcg::new(r);
    let taps = ring.as_slice();
    // The window's sums and E's early copies at phases k (SA), in one walk.
    let (last, early) = taps.split_last().unwrap_or((&Tap::EMPTY, &[]));
    let (mut pc, mut ps, mut ups) = (0i32, 0i32, 0i32);
    let (mut sc, mut ss) = last.parts();
    let mut sum = 0i32;
    for tap in early {
        let (c, s) = tap.parts();
        if tap.up != 0 {
            pc += c;
            ps += s;
            ups += 1;
            sum = sum.wrapping_add((c * sc).wrapping_add(s * ss));
        }
        sc += c;
        ss += s;
    }
    if last.up != 0 {
        let (c, s) = last.parts();
        (pc, ps, ups) = (pc + c, ps + s, ups + 1);
    }
    // The late copies at phases (k + N) mod W (SB, sign folded in): the
    // table from N mod W on, then from 0.
    let (late_b, late_a) = table.split_at(n_mod_w);
    // Phase (N + W − 1) mod W = (N mod W) − 1, or W − 1 where N mod W = 0.
    let (c, s) = table
        .get(n_mod_w.checked_sub(1).unwrap_or(w - 1))
        .copied()
        .unwrap_or_default();
    let (early_a, early_b) = early.split_at(late_a.len().min(early.len()));
    let mut state = (-i32::from(c), -i32::from(s), sum);
    state = wrap_part(early_a, late_a, state);
    state = wrap_part(early_b, late_b, state);
    (pc, ps, ups * qq, state.2)
}

/// Adds to E's sum (`.2`, wrapping) the terms T(k)·S(k) of the up-steps
/// among `taps`, T(k) the k-th entry of `phases`, with the running sum S
/// (`.0`, `.1`) moving by −T(k) after each step (SB of the derivation, sign
/// folded in).
fn wrap_part(
    taps: &[Tap],
    phases: &[(i16, i16)],
    (mut sc, mut ss, mut sum): (i32, i32, i32),
) -> (i32, i32, i32) {
    for (tap, &(c, s)) in taps.iter().zip(phases) {
        let (c, s) = (i32::from(c), i32::from(s));
        if tap.up != 0 {
            sum = sum.wrapping_add((c * sc).wrapping_add(s * ss));
        }
        sc -= c;
        ss -= s;
    }
    (sc, ss, sum)
}

/// Converts the integral X to walk steps δ for [`Trace::smoothed`]
/// (paper form; the seamless form's b-steps count half).
fn trace_scale(shift: u32, qq: i32, w: usize) -> f32 {
    (1u64 << shift) as f32 / (qq as f32 * w as f32)
}

/// Every how many samples [`find_crossing`] looks first.
const CROSSING_GRID: usize = 16;

/// Finds where the stored loop X crosses `level` and returns that index,
/// the sample nearer the level, with X there, both as offsets from the
/// lowest sample `low` (exact in `u16`).
///
/// The crossing is the one bracketed by the first sample of the grid 0, 16,
/// 32, … that is not on the side of `level` where X starts, refined by
/// bisection: about N/16 + 4 samples read instead of a walk to the first
/// crossing, which may lie half a loop away. (Samples only 16 apart cannot
/// hide more than a brief excursion; a loop whose grid never leaves the
/// start's side is walked sample by sample.) A closed loop that spans the
/// level always crosses it.
fn find_crossing<S: Sample>(xs: &[S], low: i16, level: i32) -> (usize, i32) {
    let at = |i: usize| {
        xs.get(i).map_or(
            level,
            |s| i32::from(s.to_scratch().wrapping_sub(low) as u16),
        )
    };
    let x0 = at(0);
    if xs.is_empty() || x0 == level {
        return (0, x0);
    }
    // Whether X is still strictly on the start's side.
    let before = |x: i32| if x0 > level { x > level } else { x < level };
    let mut off = CROSSING_GRID;
    while off < xs.len() && before(at(off)) {
        off += CROSSING_GRID;
    }
    let (mut a, mut b) = if off < xs.len() {
        (off - CROSSING_GRID, off)
    } else {
        match (1..xs.len()).find(|&i| !before(at(i))) {
            Some(i) => (i - 1, i),
            None => return (0, x0),
        }
    };
    // X(a) is on the start's side, X(b) is not.
    while b - a > 1 {
        let m = a + (b - a) / 2;
        if before(at(m)) {
            a = m;
        } else {
            b = m;
        }
    }
    let (xa, xb) = (at(a), at(b));
    if (xb - level).abs() <= (xa - level).abs() {
        (b, xb)
    } else {
        (a, xa)
    }
}

/// `num/den` (fine units per X unit) as a multiplier `m / 2^shift`, rounded
/// down so scaled values never overshoot, with `m` as large as the product
/// `ΔX·m` allows in `i32` for |ΔX| ≤ `vmax`: m·vmax + 2^shift ≤ 2³¹.
/// `None` if the ratio does not fit.
fn multiplier(num: i64, den: i64, vmax: i64) -> Option<(i32, u32)> {
    if num <= 0 || den <= 0 || vmax <= 0 {
        return None;
    }
    // A power of two (the seamless loop's 2¹⁶) divides by a shift.
    let m_max = if vmax & (vmax - 1) == 0 {
        (1u64 << 30) >> vmax.trailing_zeros()
    } else {
        (1u64 << 30) / vmax as u64
    }
    .max(1);
    // ratio · 2³⁰, exact floor (num < 2²⁴): one division.
    let r = ((num as u64) << 30) / den as u64;
    // The fewest dropped bits that bring r to m_max or below: r's length
    // less m_max's, or one more.
    let mut drop = (64 - r.leading_zeros()).saturating_sub(64 - m_max.leading_zeros());
    if r.checked_shr(drop).unwrap_or(0) > m_max {
        drop += 1;
    }
    let m = r.checked_shr(drop).unwrap_or(0);
    if drop > 30 || m == 0 {
        return None;
    }
    Some((m as i32, 30 - drop))
}

/// Integrates the stored ΔΔX twice and stores the scaled loop in place:
/// with ΔX(0) = `v_start`, value(i) = `start_fine` + ⌊Σ_{1≤k≤i} ΔX(k)·m/2^shift⌋
/// (error feedback keeps the running sum exact; `start_residue` is value(0)'s
/// remainder) and value(0) = `start_fine`.
/// `post` maps each value (index, fine units) to what is stored.
#[inline(never)]
fn scale_pass<S: Sample>(
    out: &mut [S],
    (v_start, start_fine, start_residue): (i32, i32, i32),
    m: i32,
    shift: u32,
    mut post: impl FnMut(usize, i32) -> i32,
) {
    let mask: i32 = ((1i64 << shift) - 1) as i32;
    let (mut fine, mut residue, mut v) = (start_fine, start_residue, v_start);
    let Some((first, rest)) = out.split_first_mut() else {
        return;
    };
    *first = S::from_fine(post(0, fine));
    for (i, s) in rest.iter_mut().enumerate() {
        v += i32::from(s.to_scratch());
        let acc = v * m + residue;
        residue = acc & mask;
        fine += acc >> shift;
        *s = S::from_fine(post(i + 1, fine));
    }
}

// ---------------------------------------------------------------------------
// Paper closure: causal smoothing, normalisation, Hann taper, split, exchange.
// ---------------------------------------------------------------------------

/// The paper's loop (Figure 6).
///
/// The open walk has u(0) = 0 and steps e(k) = ±1 from r(k), k = 1..N−1
/// (e(0) = 0 and e(k) = 0 before the start: the paper's u(n−m) = 0 for n−m < 0).
fn paper<S: Sample, T: Trace>(
    out: &mut [S],
    cfg: &AxisConfig,
    kernel: &HannKernel,
    trace: &mut T,
) -> Result<(LoopInfo, LoopScale), MotionError> {
    let Basics { n, w, table, q, qq } = Basics::of(out, cfg, kernel);
    let shift = x_shift(q, w, n);

    // Pass 2 (causal): steps in {−1, 0, +1}; V = Q²·B − cp = 2Q²·v.
    let mut main = Lcg::new(cfg.seed);
    let mut lag = Lcg::new(cfg.seed);
    let (mut pc, mut ps, mut b) = (0i32, 0i32, 0i32);
    let mut quant = Quantiser::new(shift);
    let mut x: i32 = 0;
    let mut vq_prev: i32 = 0;
    let mut extent = Extent::new(0);
    let mut speed = Extent::new(0);
    let mut ones: u32 = 0;
    let scale = trace_scale(shift, qq, w);
    let mut j = 0usize;
    for (i, s) in out.iter_mut().enumerate() {
        let enter = if i == 0 {
            0
        } else {
            step(main.next_step_bit())
        };
        ones += u32::from(enter > 0);
        // e(i−W) leaves: zero before the start and for e(0).
        let leave = if i <= w { 0 } else { step(lag.next_step_bit()) };
        let d = enter - leave;
        let (tc, ts) = table[j];
        pc += d * i32::from(tc);
        ps += d * i32::from(ts);
        b += d;
        let cp = i32::from(tc) * pc + i32::from(ts) * ps;
        let vq = quant.push(qq * b - cp);
        x += vq;
        if i == 0 {
            extent = Extent::new(x);
        }
        extent.add(x);
        speed.add(vq);
        *s = S::from_scratch((vq - vq_prev) as i16);
        vq_prev = vq;
        if T::ENABLED {
            trace.smoothed(i, x as f32 * scale);
        }
        j += 1;
        if j == w {
            j = 0;
        }
    }

    let (lo, hi) = (i64::from(extent.min), i64::from(extent.max));
    if hi - lo < MIN_EXTENT {
        return Err(MotionError::Degenerate { seed: cfg.seed });
    }
    let a1 = i64::from(cfg.range.min.millidegrees()) * i64::from(FINE_PER_MDEG);
    let a2 = i64::from(cfg.range.max.millidegrees()) * i64::from(FINE_PER_MDEG);
    let vmax = i64::from(speed.max.max(-speed.min)) + 1;
    let (m, mshift) =
        multiplier(a2 - a1, hi - lo, vmax).ok_or(MotionError::Degenerate { seed: cfg.seed })?;

    // Normalise: α1 + (X − X_min)·(α2 − α1)/(X_max − X_min), then taper with
    // the symmetric length-N Hann window (both ends exactly zero).
    let x0 = i64::from(out.first().map_or(0, |s| s.to_scratch())); // X(0) = ΔX(0) = ΔΔX(0)
    let acc0 = (x0 - lo) * i64::from(m);
    let start_fine = (a1 + (acc0 >> mshift)) as i32;
    let start_residue = (acc0 & ((1i64 << mshift) - 1)) as i32;
    let span = (n - 1) as u64;
    scale_pass(
        out,
        (x0 as i32, start_fine, start_residue),
        m,
        mshift,
        |i, fine| {
            if T::ENABLED {
                trace.normalized(i, fine);
            }
            if i == 0 || i == n - 1 {
                return 0; // the taper's ends are exactly zero
            }
            let phase = ((i as u64) << 32) / span;
            let (c, _) = idsp::cossin(phase as u32 as i32);
            // ½ − ½·cos(2πi/(N−1)) in Q31: (2³¹ − cos)/2.
            let hann = ((1i64 << 31) - i64::from(c)) >> 1;
            ((i64::from(fine) * hann + (1 << 30)) >> 31) as i32
        },
    );

    // Zero crossings: v(n) = sign x(n+1) − sign x(n) ≠ 0, n = 0..N−2, on the
    // stored angles; one is drawn with the LCG value after the walk, r(N).
    let sign = |s: &S| s.angle().millidegrees().signum();
    let crossings = out
        .windows(2)
        .filter(|p| sign(&p[1]) != sign(&p[0]))
        .count();
    let pick = main.next_index(crossings as u32) as usize;
    let split = out
        .windows(2)
        .enumerate()
        .filter(|(_, p)| sign(&p[1]) != sign(&p[0]))
        .nth(pick)
        .map_or(0, |(i, _)| i);
    let info = LoopInfo {
        split: split as u16,
        start: split as u16,
        crossings: crossings as u16,
        up_steps: ones as u16,
    };
    Ok((info, LoopScale::MDEG))
}

/// Maps samples stored with `scale` to the storage's own units
/// ([`LoopScale::MDEG`] afterwards); nothing to do if they are already.
pub(super) fn finalise<S: Sample>(out: &mut [S], scale: &LoopScale) {
    if *scale == LoopScale::MDEG {
        return;
    }
    for o in out {
        *o = S::from_fine(scale.fine(o.to_scratch()));
    }
}

#[inline]
fn step(bit: u32) -> i32 {
    (bit as i32) * 2 - 1
}
