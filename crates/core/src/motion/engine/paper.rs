//! The paper's closure (Figure 6): causal smoothing, normalisation, a
//! length-N Hann taper, and the two halves exchanged at a zero crossing.

use super::scale::{multiplier, trace_scale};
use super::{Basics, LoopInfo, Quantiser, Trace};
use crate::motion::kernel::HannKernel;
use crate::motion::lcg::Lcg;
use crate::motion::storage::{FINE_PER_MDEG, LoopScale, Sample};
use crate::motion::{AxisConfig, MotionError};

/// The paper's loop (Figure 6).
///
/// The open walk has u(0) = 0 and steps e(k) = ±1 from r(k), k = 1..N−1
/// (e(0) = 0 and e(k) = 0 before the start: the paper's u(n−m) = 0 for n−m < 0).
pub(super) fn paper<S: Sample, T: Trace, const CAP: usize>(
    out: &mut [S],
    cfg: &AxisConfig,
    kernel: &HannKernel<CAP>,
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
/// - 2^shift ≥ 2N, which bounds |X| < 2³¹.
fn x_shift(q: i32, w: usize, n: usize) -> u32 {
    let dv_bound = 3 * i64::from(q) * i64::from(q) + 8 * i64::from(q + 1) * w as i64;
    let by_acc = 64 - ((dv_bound >> 13) as u64).leading_zeros();
    let by_len = 64 - ((2 * n as u64 - 1).leading_zeros());
    by_acc.max(by_len)
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

/// Integrates the stored ΔΔX twice and stores the scaled loop in place:
/// with ΔX(0) = `v_start`, value(i) = `start_fine` + ⌊Σ_{1≤k≤i} ΔX(k)·m/2^shift⌋
/// (error feedback keeps the running sum exact; `start_residue` is value(0)'s
/// remainder) and value(0) = `start_fine`.
/// `post` maps each value (index, fine units) to what is stored.
fn scale_pass<S: Sample>(
    out: &mut [S],
    (v_start, start_fine, start_residue): (i32, i32, i32),
    m: i32,
    shift: u32,
    mut post: impl FnMut(usize, i32) -> i32,
) {
    let mut quantiser = Quantiser::with_residue(shift, start_residue);
    let (mut fine, mut v) = (start_fine, v_start);
    let Some((first, rest)) = out.split_first_mut() else {
        return;
    };
    *first = S::from_fine(post(0, fine));
    for (i, s) in rest.iter_mut().enumerate() {
        v += i32::from(s.to_scratch());
        fine += quantiser.push(v * m);
        *s = S::from_fine(post(i + 1, fine));
    }
}

#[inline]
fn step(bit: u32) -> i32 {
    (bit as i32) * 2 - 1
}
