//! The seamless closure: a periodic walk smoothed circularly, started where
//! it crosses the level of the neutral pose.
//!
//! # Closing the loop exactly
//!
//! The detrend q is the loop's total Σ V divided by N. The zero-sum table makes
//! that total Q²·W·(up steps) exactly, except for the windows that wrap around
//! the loop's end, whose steps are seen at table phases shifted by N mod W;
//! [`initial_window`] computes their share E exactly in O(W). With q =
//! ⌊(Q²·W·ups − E)/N⌋ the remainder is below N < 2^shift, so the quantised
//! integral returns exactly to its start.

use super::scale::{multiplier, trace_scale};
use super::sweep::{Ring, Sweep, initial_window};
use super::{Basics, LoopInfo, Trace};
use crate::motion::kernel::HannKernel;
use crate::motion::lcg::Lcg;
use crate::motion::storage::{FINE_PER_MDEG, LoopScale, Sample};
use crate::motion::{AxisConfig, MotionError};

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
pub(super) fn seamless<S: Sample, T: Trace, const CAP: usize>(
    out: &mut [S],
    cfg: &AxisConfig,
    kernel: &HannKernel<CAP>,
    trace: &mut T,
) -> Result<(LoopInfo, LoopScale), MotionError> {
    let basics = Basics::of(out, cfg, kernel);
    let Basics { n, w, qq, .. } = basics;
    let shift = raw_shift(qq, w, n);
    let Smoothed {
        ups,
        first,
        mut lo,
        mut hi,
    } = smooth::<S, CAP>(out, cfg.seed, &basics, shift);
    // X spans at most 65535 raw units, so that its offsets from the lowest
    // sample are exact in `u16`; a wider loop than `raw_shift` expects is
    // quantised again.
    let mut step_log = shift;
    if hi - lo > i32::from(u16::MAX) {
        let k = requantise(out, first, lo, hi);
        (lo, hi, step_log) = (lo >> k, hi >> k, shift + k);
    }
    let low = lo as i16;
    if T::ENABLED {
        // X along the loop, for the observer (previews only).
        let scale = trace_scale(step_log, qq, w) * 2.0;
        for (t, o) in out.iter().enumerate() {
            let offset = i32::from(o.to_scratch().wrapping_sub(low) as u16);
            trace.smoothed((w - 1 + t) % n, (lo + offset) as f32 * scale);
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
    // As a loop index.
    let split = (start + w - 1) % n;

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
        up_steps: ups as u16,
    };
    Ok((info, scale))
}

/// The smoothed loop as [`smooth`] leaves it.
struct Smoothed {
    /// Up-steps among the walk's N steps.
    ups: u32,
    /// X of the first output (`out[0]`).
    first: i32,
    /// The lowest and the highest X.
    lo: i32,
    hi: i32,
}

/// Passes 1 and 2: the circular walk of `seed` smoothed and detrended, its
/// quantised integral X stored in `out` in generation order: `out[t]`
/// belongs to loop index (W−1+t) mod N.
fn smooth<S: Sample, const CAP: usize>(
    out: &mut [S],
    seed: u32,
    basics: &Basics,
    shift: u32,
) -> Smoothed {
    let Basics {
        n, w, table, qq, ..
    } = *basics;
    // Pass 1: count the up-steps of the whole circular walk.
    let ups = count_ups(seed, n);
    // The initial window, steps k = 0..W−1 (output n = W−1), fills the tap
    // ring and gives the wrap correction E for the detrend.
    let mut walk = Lcg::new(seed);
    let mut ring = Ring::<CAP>::new();
    let n_mod_w = n % w;
    let window = initial_window(table, n_mod_w, &mut walk, qq, &mut ring);
    let taps = ring.as_mut_slice();
    let q = detrend(qq * w as i32, ups, window.wrap, n);

    // Pass 2. The first output, n = W−1, is the initial window, at residue
    // W−1 (N ≥ 2W: `head` holds it and more).
    let (head, tail) = out.split_at_mut(n - w + 1);
    let (Some((first, head)), Some(last)) = (head.split_first_mut(), table.last()) else {
        return Smoothed {
            ups,
            first: 0,
            lo: 0,
            hi: 0,
        };
    };
    let mut sweep = Sweep::start(&window, q, *last, shift, first);
    let x_first = sweep.x();
    // Slides s = 1..N−1: step W−1+s enters, step s−1 leaves, both at residue
    // (s−1) mod W. When the entering index reaches N (s = N−W+1) the circular
    // walk wraps to e(0); that slide's residue is (N − W) mod W = N mod W.
    sweep.run(head, taps, 0, &mut walk, qq, shift);
    sweep.run(tail, taps, n_mod_w, &mut Lcg::new(seed), qq, shift);
    debug_assert_eq!(sweep.x(), 0, "the seamless loop closes exactly");
    let (lo, hi) = sweep.extent();
    Smoothed {
        ups,
        first: x_first,
        lo,
        hi,
    }
}

/// The detrend q = ⌊(Q²·W·ups − E)/N⌋ (see the module docs), with
/// `qqw` = Q²·W < 2²⁹, `ups` ≤ N ≤ 8192 and |E| < 2²⁴, in 32-bit steps (a
/// 64-bit floor division costs 720 instructions more for the default set).
/// With Q²·W = a·N + b, b < N, the quotient is a·ups + ⌊(b·ups − E)/N⌋,
/// where |b·ups − E| < 2²⁶ + 2²⁴.
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

/// The bit length of ⌊y/40⌋ without dividing (a 64-bit division here costs
/// 1,520 instructions more for the default set).
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
fn count_ups(seed: u32, n: usize) -> u32 {
    let mut walk = Lcg::new(seed);
    let mut ups = 0;
    // Four steps a turn: 4,000 instructions fewer for the default set.
    for _ in 0..n / 4 {
        ups += walk.next_step_bit()
            + walk.next_step_bit()
            + walk.next_step_bit()
            + walk.next_step_bit();
    }
    for _ in 0..n % 4 {
        ups += walk.next_step_bit();
    }
    ups
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
