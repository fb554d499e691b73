//! The Hann smoothing kernel in the table form used by the O(N) smoother.
//!
//! The kernel is the periodic Hann window of `W` taps,
//! h(m) = ½ − ½·cos(2πm/W), m = 0..W−1 (the DFT-even form; h(0) = 0, so W−1 taps
//! carry weight and Σh = W/2 exactly). Its cosine part is applied through a
//! sliding phasor (see [`super::engine`]), which needs one table of
//! `(Q·cos 2πj/W, Q·sin 2πj/W)`, j = 0..W−1, in integers.
//!
//! Table scale: `Q = ⌊√(2²⁹ / W)⌋ − 1`, so that `Q²·W < 2²⁹` and every product
//! of the smoother fits an `i32` (the bound is worked out in `engine/mod.rs`).
//! The table is made exactly zero-sum (Σcos = Σsin = 0 over a period), which
//! makes the smoother's loop sums exact; the sine column is odd by
//! construction and the cosine column absorbs its rounding residue in its
//! j = 0 entry (a change of a few parts in 10⁴ of one tap).

use super::error::MotionError;
use super::limits::{MAX_WINDOW, MIN_WINDOW};

/// The kernel table for one window length `W`, of at most `CAP` taps.
///
/// `CAP` is the largest window the kernel can be built for, [`MAX_WINDOW`]
/// unless told otherwise. It sizes the table, and the smoother's ring of
/// taps on the stack while a loop is computed (16 bytes a tap): an image
/// whose windows are all short sets it to its longest window and keeps
/// 10 KB of stack for other things (see [`HeadTrajectories`]).
///
/// [`HeadTrajectories`]: super::HeadTrajectories
#[derive(Clone, Debug)]
pub struct HannKernel<const CAP: usize = { MAX_WINDOW as usize }> {
    window: u16,
    q: i32,
    /// The entries j = 0..W−1; a vector, so that a kernel is made without
    /// clearing (or moving) all of its capacity.
    table: heapless::Vec<(i16, i16), CAP>,
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
        let mut kernel = Self::empty();
        kernel.rebuild(window)?;
        Ok(kernel)
    }
}

impl<const CAP: usize> HannKernel<CAP> {
    /// The longest window this kernel takes: `CAP`, which must lie in
    /// `MIN_WINDOW..=MAX_WINDOW` (checked when the type is used).
    pub const CAPACITY: u16 = {
        assert!(
            CAP >= MIN_WINDOW as usize && CAP <= MAX_WINDOW as usize,
            "a kernel's capacity lies in MIN_WINDOW..=MAX_WINDOW"
        );
        CAP as u16
    };

    /// A kernel of no taps, to [`HannKernel::rebuild`] in place.
    #[must_use]
    pub const fn empty() -> Self {
        Self {
            window: 0,
            q: 0,
            table: heapless::Vec::new(),
        }
    }

    /// Rebuilds the table in place for `window` taps (no 2 KiB move).
    ///
    /// # Errors
    /// As [`HannKernel::new`], with [`HannKernel::CAPACITY`] in place of
    /// [`MAX_WINDOW`]; the kernel is left unchanged on error.
    pub fn rebuild(&mut self, window: u16) -> Result<(), MotionError> {
        if window < MIN_WINDOW {
            return Err(MotionError::WindowTooSmall {
                window,
                min: MIN_WINDOW,
            });
        }
        if window > Self::CAPACITY {
            return Err(MotionError::WindowTooLarge {
                window,
                max: Self::CAPACITY,
            });
        }
        if window == self.window {
            return Ok(());
        }
        let w = usize::from(window);
        let q = ((1u32 << 29) / u32::from(window)).isqrt() as i32 - 1;
        // 32-bit phase, 2³² = one turn (idsp's convention: i32::MIN is −π):
        // phase(j) = ⌊j·2³²/W⌋, stepped exactly (Bresenham on the remainder).
        // ⌊2³²/W⌋ and 2³² mod W from (2³² − 1)/W, in 32 bits.
        let (mut step, mut rem) = (u32::MAX / w as u32, u32::MAX % w as u32 + 1);
        if rem == w as u32 {
            (step, rem) = (step + 1, 0);
        }
        let (mut phase, mut frac) = (0u32, 0u32);
        // Scale from ±2³¹ full scale to ±Q, rounding to nearest:
        // (x >> 15)·Q < 2¹⁶·2¹⁴ fits i32; the dropped bits move the result
        // by less than Q/2¹⁶ < 0.21 LSB.
        let scale = |x: i32| -> i16 { (((x >> 15) * q + (1 << 15)) >> 16) as i16 };
        let mut cos_sum: i32 = 0;
        self.table.clear();
        // Cannot fail: w ≤ CAP, the capacity.
        let _ = self.table.resize(w, (0, 0));
        // The entries j = 0..=W/2 from the sine/cosine, the rest by symmetry.
        let (head, tail) = self.table.split_at_mut((w / 2 + 1).min(w));
        for (j, e) in head.iter_mut().enumerate() {
            let (c, s) = idsp::cossin(phase as i32);
            // sin 0 = sin π = 0 exactly.
            let ts = if j == 0 || 2 * j == w { 0 } else { scale(s) };
            *e = (scale(c), ts);
            cos_sum += i32::from(e.0);
            phase = phase.wrapping_add(step);
            frac += rem;
            if frac >= u32::from(window) {
                frac -= u32::from(window);
                phase = phase.wrapping_add(1);
            }
        }
        // Mirror: cos(2π(W−j)/W) = cos(2πj/W), sin(2π(W−j)/W) = −sin(2πj/W):
        // entry W−1 from j = 1, W−2 from j = 2, … (j = W/2 is its own
        // mirror when W is even).
        for (e, &(tc, ts)) in tail.iter_mut().rev().zip(head.iter().skip(1)) {
            *e = (tc, -ts);
            cos_sum += i32::from(tc);
        }
        // Zero-sum cosine column: fold the rounding residue into j = 0.
        if let Some(e) = self.table.first_mut() {
            e.0 = (i32::from(e.0) - cos_sum) as i16;
        }
        self.window = window;
        self.q = q;
        Ok(())
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
        &self.table
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
