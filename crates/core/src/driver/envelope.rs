//! Fade envelope: smoothstep gain that fades the idle motion in and out.
//!
//! The gain at level `l` µs into a fade of `n` µs is `S(x) = x²(3 − 2x)` at
//! `x = ⌊l·2¹⁶/n⌋` (Q16), rounded down. The envelope keeps `x` and the
//! remainder `l·2¹⁶ mod n` as the level moves by one frame period `F` a
//! frame, adding or taking away `⌊F·2¹⁶/n⌋` and `F·2¹⁶ mod n` (worked out
//! with the envelope, and again when the frame period changes) with a
//! carry: exactly the quotient, and no division on the frame path. A step
//! that would pass an end stops on it. `S` is formed from 16-bit halves:
//! `x² = qₕ·2¹⁶ + qₗ`, `c = 3·2¹⁶ − 2x = cₕ·2¹⁶ + cₗ`, `⌊x²c/2³²⌋ = ⌊(qₕc +
//! qₗcₕ + ⌊qₗcₗ/2¹⁶⌋)/2¹⁶⌋`. Every partial sum is at most `x²c/2¹⁶ =
//! 2³²·S(x/2¹⁶) < 2³²` for `x < 2¹⁶`: `u32` throughout.

/// Gain scale: Q16, 1.0 = 65 536.
pub(crate) const UNITY: u32 = 1 << 16;

/// The longest fade, µs (about 35 minutes).
pub(crate) const MAX_FADE: u32 = (1 << 31) - 1;

/// A gain ramping between 0 and 1 over `fade` µs along a smoothstep
/// (3x² − 2x³: continuous in value and slope, flat at both ends), one
/// frame period a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Envelope {
    /// The fade, µs (below 2³¹: the remainders' sums fit `u32`; 0: no
    /// fade).
    fade: u32,
    /// µs into the fade, `0..=fade`.
    level: u32,
    /// The frame period, µs.
    frame: u32,
    stopping: bool,
    /// The last frame moved the level a whole frame period (not onto an
    /// end, and not held since).
    stepped: bool,
    /// `⌊level·2¹⁶/fade⌋` and `level·2¹⁶ mod fade` (0 and 0 when `fade`
    /// is 0).
    x: u32,
    rem: u32,
    /// `⌊F·2¹⁶/fade⌋` and `F·2¹⁶ mod fade`: what one frame adds.
    step: u32,
    step_rem: u32,
}

impl Envelope {
    /// An envelope at zero gain, about to fade in over `fade` µs, one frame
    /// every `frame` µs.
    pub(crate) const fn new(fade: u32, frame: u32) -> Self {
        let mut envelope = Self {
            fade: if fade > MAX_FADE { MAX_FADE } else { fade },
            level: 0,
            frame: 0,
            stopping: false,
            stepped: false,
            x: 0,
            rem: 0,
            step: 0,
            step_rem: 0,
        };
        envelope.set_frame_period(frame);
        envelope
    }

    /// Frames come `frame` µs apart from the next frame on. The last frame
    /// moved the level by the old period towards the next frame's; if it
    /// moved a whole period, the level moves by the difference too, so that
    /// the next frame's gain is the one `frame` µs after the last's.
    pub(crate) const fn set_frame_period(&mut self, frame: u32) {
        if self.stepped {
            self.shift(frame as i64 - self.frame as i64);
        }
        self.frame = frame;
        // F·2¹⁶ < 2⁴⁸: u64, divided here, not on the frame path.
        let scaled = (frame as u64) << 16;
        let (step, step_rem) = match (
            scaled.checked_div(self.fade as u64),
            scaled.checked_rem(self.fade as u64),
        ) {
            (Some(q), Some(r)) => (q, r),
            _ => (0, 0),
        };
        // A step past the whole fade stops on its end anyway.
        self.step = if step > UNITY as u64 {
            UNITY
        } else {
            step as u32
        };
        self.step_rem = step_rem as u32;
    }

    /// Puts the level `by` µs further along the way it moves (negative:
    /// back). Divides (between frames, once per change of the frame
    /// period).
    const fn shift(&mut self, by: i64) {
        let moving = if self.stopping {
            self.level > 0
        } else {
            self.level < self.fade
        };
        if !moving {
            return;
        }
        let by = if self.stopping { -by } else { by };
        let level = self.level as i64 + by;
        let level = if level < 0 {
            0
        } else if level > self.fade as i64 {
            self.fade as i64
        } else {
            level
        };
        self.level = level as u32;
        let scaled = (level as u64) << 16;
        let fade = self.fade as u64;
        (self.x, self.rem) = match (scaled.checked_div(fade), scaled.checked_rem(fade)) {
            (Some(q), Some(r)) => (q as u32, r as u32),
            _ => (0, 0),
        };
    }

    /// The gain of this frame, the level then moved one frame on: the
    /// frame path's [`gain`](Self::gain) and [`advance`](Self::advance).
    /// Faded in and not stopping, the gain stays 1 and nothing moves: one
    /// comparison.
    #[inline]
    pub(crate) const fn next_gain(&mut self) -> u32 {
        if self.level >= self.fade && !self.stopping {
            return UNITY;
        }
        let gain = self.gain();
        self.advance();
        gain
    }

    /// The current gain in Q16 (`0..=65 536`).
    pub(crate) const fn gain(&self) -> u32 {
        if self.level >= self.fade {
            return if self.fade == 0 && self.stopping {
                0
            } else {
                UNITY
            };
        }
        if self.level == 0 {
            return 0;
        }
        // 0 < level < fade, so 0 < x < 2¹⁶.
        smoothstep(self.x)
    }

    /// Moves the level one frame on (towards zero while stopping), onto an
    /// end rather than past it.
    pub(crate) const fn advance(&mut self) {
        self.stepped = false;
        if self.stopping {
            if self.level <= self.frame {
                (self.level, self.x, self.rem) = (0, 0, 0);
            } else {
                self.stepped = true;
                self.level -= self.frame;
                // (x, rem) − (step, step_rem), borrowing `fade` from x; the
                // result is level·2¹⁶ ≥ 0 divided by fade.
                if self.rem < self.step_rem {
                    self.rem += self.fade - self.step_rem;
                    self.x -= self.step + 1;
                } else {
                    self.rem -= self.step_rem;
                    self.x -= self.step;
                }
            }
        } else if self.level < self.fade {
            if self.fade - self.level <= self.frame {
                (self.level, self.x, self.rem) = (self.fade, UNITY, 0);
            } else {
                self.stepped = true;
                self.level += self.frame;
                // (x, rem) + (step, step_rem), carrying when rem reaches
                // fade (both below it: no overflow as written).
                if self.rem >= self.fade - self.step_rem {
                    self.rem -= self.fade - self.step_rem;
                    self.x += self.step + 1;
                } else {
                    self.rem += self.step_rem;
                    self.x += self.step;
                }
            }
        }
    }

    /// Fade out (`true`) or in (`false`) from the current gain.
    pub(crate) const fn set_stopping(&mut self, stopping: bool) {
        self.stopping = stopping;
        self.stepped = false;
    }

    /// A frame without the fade (relaxed): the level stays where it is.
    pub(crate) const fn hold(&mut self) {
        self.stepped = false;
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
