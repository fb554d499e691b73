//! Fade envelope: smoothstep gain that fades the idle motion in and out.
//!
//! The gain at level `l` µs into a fade of `n` µs is `S(x) = x²(3 − 2x)` at
//! `x = ⌊l·2¹⁶/n⌋` (Q16), rounded down (0 for `l ≤ 0`, 1 from `l = n` on).
//! The envelope keeps `x` and the remainder `l·2¹⁶ mod n` as the level
//! moves by one frame period `F` a frame, adding or taking away
//! `⌊F·2¹⁶/n⌋` and `F·2¹⁶ mod n` (worked out with the envelope, and again
//! when the frame period changes) with a carry: exactly the quotient, and
//! no division on the frame path. A step that would pass an end stops on
//! it. `S` is formed from 16-bit halves: `x² = qₕ·2¹⁶ + qₗ`, `c = 3·2¹⁶ −
//! 2x = cₕ·2¹⁶ + cₗ`, `⌊x²c/2³²⌋ = ⌊(qₕc + qₗcₕ + ⌊qₗcₗ/2¹⁶⌋)/2¹⁶⌋`. Every
//! partial sum is at most `x²c/2¹⁶ = 2³²·S(x/2¹⁶) < 2³²` for `x < 2¹⁶`:
//! `u32` throughout.
//!
//! The level is time: the fade-in after the start begins [`START_HOLD`]
//! after the start frame (its level starts that far below 0), whatever the
//! frame rate.

use crate::units::Microseconds;

/// Gain scale: Q16, 1.0 = 65 536.
pub(crate) const UNITY: u32 = 1 << 16;

/// The longest fade, µs (about 35 minutes).
pub(crate) const MAX_FADE: u32 = (1 << 31) - 1;

/// How long the neutral pulses hold after the start frame before the
/// fade-in begins: one frame at 50 Hz, the same time at any rate.
pub const START_HOLD: Microseconds = Microseconds(20_000);

/// A gain ramping between 0 and 1 over `fade` µs along a smoothstep
/// (3x² − 2x³: continuous in value and slope, flat at both ends), one
/// frame period a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Envelope {
    /// The fade, µs (below 2³¹: the remainders' sums fit `u32`; 0: no
    /// fade).
    fade: u32,
    /// µs into the fade, `−START_HOLD..=fade` (below 0 only before the
    /// fade-in begins).
    level: i32,
    /// The frame period, µs.
    frame: u32,
    stopping: bool,
    /// The last frame moved the level a whole frame period (not onto an
    /// end, and not held since).
    stepped: bool,
    /// `⌊level·2¹⁶/fade⌋` and `level·2¹⁶ mod fade` (0 and 0 when `fade`
    /// is 0; `x` below 0 before the fade-in begins).
    x: i32,
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

    /// The start frame was written (the neutral pulses, at time 0): the
    /// fade-in begins [`START_HOLD`] after it, and the next frame comes a
    /// frame period after it.
    pub(crate) const fn start(&mut self) {
        if self.fade == 0 || self.stopping {
            return;
        }
        self.set_level(-(START_HOLD.0 as i64));
        self.advance();
    }

    /// Frames come `frame` µs apart from the next frame on. The last frame
    /// moved the level by the old period towards the next frame's; if it
    /// moved a whole period, the level moves by the difference too, so that
    /// the next frame's gain is the one `frame` µs after the last's.
    pub(crate) const fn set_frame_period(&mut self, frame: u32) {
        if self.stepped {
            let by = frame as i64 - self.frame as i64;
            let by = if self.stopping { -by } else { by };
            let level = self.level as i64 + by;
            let top = self.fade as i64;
            self.set_level(if level < 0 && self.stopping {
                0
            } else if level > top {
                top
            } else {
                level
            });
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

    /// Puts the level at `level` µs (within `−START_HOLD..=fade`), `x` and
    /// the remainder with it. Divides (between frames).
    const fn set_level(&mut self, level: i64) {
        let fade = self.fade as i64;
        if fade == 0 {
            return;
        }
        self.level = level as i32;
        // ⌊level·2¹⁶/fade⌋ rounded down, also below 0.
        let scaled = level << 16;
        let (q, r) = match (scaled.checked_div(fade), scaled.checked_rem(fade)) {
            (Some(q), Some(r)) => (q, r),
            _ => (0, 0),
        };
        (self.x, self.rem) = if r < 0 {
            ((q - 1) as i32, (r + fade) as u32)
        } else {
            (q as i32, r as u32)
        };
    }

    /// The gain of this frame, the level then moved one frame on: the
    /// frame path's [`gain`](Self::gain) and [`advance`](Self::advance).
    /// Faded in and not stopping, the gain stays 1 and nothing moves: one
    /// comparison.
    #[inline]
    pub(crate) const fn next_gain(&mut self) -> u32 {
        if self.level >= self.fade as i32 && !self.stopping {
            return UNITY;
        }
        let gain = self.gain();
        self.advance();
        gain
    }

    /// The current gain in Q16 (`0..=65 536`).
    pub(crate) const fn gain(&self) -> u32 {
        if self.level >= self.fade as i32 {
            return if self.fade == 0 && self.stopping {
                0
            } else {
                UNITY
            };
        }
        if self.level <= 0 {
            return 0;
        }
        // 0 < level < fade, so 0 < x < 2¹⁶.
        smoothstep(self.x as u32)
    }

    /// Moves the level one frame on (towards zero while stopping), onto an
    /// end rather than past it.
    pub(crate) const fn advance(&mut self) {
        self.stepped = false;
        if self.stopping {
            if self.level <= self.frame as i32 {
                (self.level, self.x, self.rem) = (0, 0, 0);
            } else {
                self.stepped = true;
                self.level -= self.frame as i32;
                // (x, rem) − (step, step_rem), borrowing `fade` from x; the
                // result is level·2¹⁶ ≥ 0 divided by fade. A frame longer
                // than the fade (its step clamped) divides instead.
                if self.step >= UNITY {
                    self.set_level(self.level as i64);
                } else if self.rem < self.step_rem {
                    self.rem += self.fade - self.step_rem;
                    self.x -= self.step as i32 + 1;
                } else {
                    self.rem -= self.step_rem;
                    self.x -= self.step as i32;
                }
            }
        } else if self.level < self.fade as i32 {
            // fade − level < 2³¹ + START_HOLD: u32.
            if (self.fade as i64 - self.level as i64) <= self.frame as i64 {
                (self.level, self.x, self.rem) = (self.fade as i32, UNITY as i32, 0);
            } else {
                self.stepped = true;
                self.level += self.frame as i32;
                // (x, rem) + (step, step_rem), carrying when rem reaches
                // fade (both below it: no overflow as written); a frame
                // longer than the fade (its step clamped) divides instead.
                if self.step >= UNITY {
                    self.set_level(self.level as i64);
                } else if self.rem >= self.fade - self.step_rem {
                    self.rem -= self.fade - self.step_rem;
                    self.x += self.step as i32 + 1;
                } else {
                    self.rem += self.step_rem;
                    self.x += self.step as i32;
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

#[cfg(test)]
mod tests {
    use super::{Envelope, UNITY};

    /// A fade shorter than a frame (2 ms at 333 Hz): the gain still rises
    /// from 0 to 1 and falls back, never outside them.
    #[test]
    fn a_fade_shorter_than_a_frame_stays_within_its_gains() {
        let mut envelope = Envelope::new(2_000, 3_000);
        envelope.start();
        let mut last = 0;
        for _ in 0..10 {
            let gain = envelope.next_gain();
            assert!(gain <= UNITY && gain >= last, "{gain} after {last}");
            last = gain;
        }
        assert_eq!(last, UNITY);
        envelope.set_stopping(true);
        for _ in 0..10 {
            let gain = envelope.next_gain();
            assert!(gain <= last, "{gain} after {last}");
            last = gain;
        }
        assert_eq!(last, 0);
    }
}
