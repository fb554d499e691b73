//! Fade envelope: smoothstep gain that fades the idle motion in and out.
//!
//! The gain at level `l` of `n` frames is `S(x) = x²(3 − 2x)` at
//! `x = ⌊l·2¹⁶/n⌋` (Q16), rounded down. The envelope keeps `x` and the
//! remainder `l·2¹⁶ mod n` as the level moves by one a frame, adding or
//! taking away `⌊2¹⁶/n⌋` and `2¹⁶ mod n` (worked out with the envelope) with
//! a carry: exactly the quotient, and no division on the frame path. `S` is
//! formed from 16-bit halves: `x² = qₕ·2¹⁶ + qₗ`, `c = 3·2¹⁶ − 2x = cₕ·2¹⁶ +
//! cₗ`, `⌊x²c/2³²⌋ = ⌊(qₕc + qₗcₕ + ⌊qₗcₗ/2¹⁶⌋)/2¹⁶⌋`. Every partial sum is at
//! most `x²c/2¹⁶ = 2³²·S(x/2¹⁶) < 2³²` for `x < 2¹⁶`: `u32` throughout.

/// Gain scale: Q16, 1.0 = 65 536.
pub(crate) const UNITY: u32 = 1 << 16;

/// A gain ramping between 0 and 1 over `frames` frames along a smoothstep
/// (3x² − 2x³: continuous in value and slope, flat at both ends).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Envelope {
    frames: u32,
    level: u32,
    stopping: bool,
    /// `⌊level·2¹⁶/frames⌋` and `level·2¹⁶ mod frames` (0 and 0 when
    /// `frames` is 0).
    x: u32,
    rem: u32,
    /// `⌊2¹⁶/frames⌋` and `2¹⁶ mod frames`: what one level adds.
    step: u32,
    step_rem: u32,
}

impl Envelope {
    /// An envelope at zero gain, about to fade in over `frames` frames.
    pub(crate) const fn new(frames: u32) -> Self {
        let (step, step_rem) = match (UNITY.checked_div(frames), UNITY.checked_rem(frames)) {
            (Some(q), Some(r)) => (q, r),
            _ => (0, 0),
        };
        Self {
            frames,
            level: 0,
            stopping: false,
            x: 0,
            rem: 0,
            step,
            step_rem,
        }
    }

    /// The gain of this frame, the level then moved one frame on: the
    /// frame path's [`gain`](Self::gain) and [`advance`](Self::advance).
    /// Faded in and not stopping, the gain stays 1 and nothing moves: one
    /// comparison.
    #[inline]
    pub(crate) const fn next_gain(&mut self) -> u32 {
        if self.level >= self.frames && !self.stopping {
            return UNITY;
        }
        let gain = self.gain();
        self.advance();
        gain
    }

    /// The current gain in Q16 (`0..=65 536`).
    pub(crate) const fn gain(&self) -> u32 {
        if self.level >= self.frames {
            return if self.frames == 0 && self.stopping {
                0
            } else {
                UNITY
            };
        }
        if self.level == 0 {
            return 0;
        }
        // 0 < level < frames, so 0 < x < 2¹⁶.
        smoothstep(self.x)
    }

    /// Moves the level one frame on (towards zero while stopping).
    pub(crate) const fn advance(&mut self) {
        if self.stopping {
            if self.level > 0 {
                self.level -= 1;
                // (x, rem) − (step, step_rem), borrowing `frames` from x;
                // the result is level·2¹⁶ ≥ 0 divided by frames.
                if self.rem < self.step_rem {
                    self.rem += self.frames - self.step_rem;
                    self.x -= self.step + 1;
                } else {
                    self.rem -= self.step_rem;
                    self.x -= self.step;
                }
            }
        } else if self.level < self.frames {
            self.level += 1;
            // (x, rem) + (step, step_rem), carrying when rem reaches
            // frames (both below it: no overflow as written).
            if self.rem >= self.frames - self.step_rem {
                self.rem -= self.frames - self.step_rem;
                self.x += self.step + 1;
            } else {
                self.rem += self.step_rem;
                self.x += self.step;
            }
        }
    }
    /// Fade out (`true`) or in (`false`) from the current gain.
    pub(crate) const fn set_stopping(&mut self, stopping: bool) {
        self.stopping = stopping;
    }

    /// Whether a stop was requested and the gain has reached zero.
    pub(crate) const fn is_stopped(&self) -> bool {
        self.stopping && self.gain() == 0
    }

    /// Whether the fade-out was requested.
    pub(crate) const fn is_stopping(&self) -> bool {
        self.stopping
    }
}

/// `⌊x²(3·2¹⁶ − 2x)/2³²⌋` for `x < 2¹⁶` (see the module docs).
const fn smoothstep(x: u32) -> u32 {
    let q = x * x;
    let c = 3 * UNITY - 2 * x;
    let (qh, ql) = (q >> 16, q & 0xFFFF);
    let (ch, cl) = (c >> 16, c & 0xFFFF);
    (qh * c + ql * ch + ((ql * cl) >> 16)) >> 16
}
