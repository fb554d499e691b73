//! The Hann smoothing kernel in the table form used by the O(N) smoother.
//!
//! The kernel is the periodic Hann window of `W` taps,
//! h(m) = ½ − ½·cos(2πm/W), m = 0..W−1 (the DFT-even form; h(0) = 0, so W−1 taps
//! carry weight and Σh = W/2 exactly). Its cosine part is applied through a
//! sliding phasor (see [`super::engine`]), which needs one table of
//! `(Q·cos 2πj/W, Q·sin 2πj/W)`, j = 0..W−1, in integers.
//!
//! Table scale: `Q = ⌊√(2²⁹ / W)⌋ − 1`, so that `Q²·W < 2²⁹` and every product
//! of the smoother fits an `i32` (the bound is worked out in `engine.rs`).
//! The table is made exactly zero-sum (Σcos = Σsin = 0 over a period), which
//! makes the smoother's loop sums exact; the sine column is odd by
//! construction and the cosine column absorbs its rounding residue in its
//! j = 0 entry (a change of a few parts in 10⁴ of one tap).

use super::MotionError;

/// Smallest supported window (taps).
pub const MIN_WINDOW: u16 = 3;
/// Largest supported window (taps); bounds the table (4 bytes a tap).
pub const MAX_WINDOW: u16 = 511;

/// The kernel table for one window length `W`.
#[derive(Clone, Debug)]
pub struct HannKernel {
    window: u16,
    q: i32,
    table: [(i16, i16); MAX_WINDOW as usize],
}

/// Integer square root (floor), for the table scale.
const fn isqrt(v: u32) -> u32 {
    let mut lo = 0u32;
    let mut hi = 1u32 << 16;
    while hi - lo > 1 {
        let mid = u32::midpoint(lo, hi);
        if (mid as u64) * (mid as u64) <= v as u64 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

impl HannKernel {
    /// Builds the table for a window of `window` taps.
    ///
    /// Costs about W/2 evaluations of a table-driven sine/cosine; the three axes
    /// of a head share one kernel when their windows are equal.
    ///
    /// # Errors
    /// [`MotionError::WindowTooSmall`] below [`MIN_WINDOW`] and
    /// [`MotionError::WindowTooLarge`] above [`MAX_WINDOW`].
    pub fn new(window: u16) -> Result<Self, MotionError> {
        if window < MIN_WINDOW {
            return Err(MotionError::WindowTooSmall {
                window,
                min: MIN_WINDOW,
            });
        }
        if window > MAX_WINDOW {
            return Err(MotionError::WindowTooLarge {
                window,
                max: MAX_WINDOW,
            });
        }
        let w = u32::from(window);
        let q = isqrt((1u32 << 29) / w) as i32 - 1;
        let mut table = [(0i16, 0i16); MAX_WINDOW as usize];
        let half = (w / 2) as usize;
        let mut cos_sum: i32 = 0;
        for j in 0..=half {
            // 32-bit phase, 2³² = one turn (idsp's convention: i32::MIN is −π).
            let phase = ((j as u64) << 32) / u64::from(w);
            let (c, s) = idsp::cossin(phase as u32 as i32);
            // Scale from ±2³¹ full scale to ±Q, rounding to nearest.
            let scale =
                |x: i32| -> i16 { ((i64::from(x) * i64::from(q) + (1 << 30)) >> 31) as i16 };
            let (tc, mut ts) = (scale(c), scale(s));
            if j == 0 || 2 * j == w as usize {
                ts = 0; // sin 0 = sin π = 0 exactly
            }
            table[j] = (tc, ts);
            cos_sum += i32::from(tc);
            let mirror = w as usize - j;
            if j != 0 && mirror != j && mirror < w as usize {
                table[mirror] = (tc, -ts);
                cos_sum += i32::from(tc);
            }
        }
        // Zero-sum cosine column: fold the rounding residue into j = 0.
        table[0].0 = (i32::from(table[0].0) - cos_sum) as i16;
        Ok(Self { window, q, table })
    }

    /// The window length W.
    #[must_use]
    pub const fn window(&self) -> u16 {
        self.window
    }

    /// The table scale Q.
    #[must_use]
    pub const fn scale(&self) -> i32 {
        self.q
    }

    /// The table entries `(Q·cos 2πj/W, Q·sin 2πj/W)` for j = 0..W−1.
    #[must_use]
    pub fn table(&self) -> &[(i16, i16)] {
        &self.table[..self.window as usize]
    }

    /// The tap weights the table realises, h(m) ≈ ½ − ½·cos(2πm/W), for tests and plots.
    #[must_use]
    pub fn tap(&self, m: usize) -> f32 {
        let t = self.table();
        let (c0, s0) = t[0];
        let (cm, sm) = t[m % t.len()];
        // cos(ω·m) = cos ωm cos 0 + sin ωm sin 0, exactly as the smoother forms it.
        let qq = (self.q as f32) * (self.q as f32);
        0.5 - 0.5 * (f32::from(cm) * f32::from(c0) + f32::from(sm) * f32::from(s0)) / qq
    }
}
