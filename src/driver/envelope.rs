//! Fade envelope: smoothstep gain that fades the idle motion in and out.
//!
//! The gain at level `l` of `n` frames is `S(x) = x²(3 − 2x)` at
//! `x = ⌊l·2¹⁶/n⌋` (Q16), rounded down: one `u32` division while the level
//! ramps (`l·2¹⁶ < 2³²` for `n ≤ 2¹⁶` frames, 22 minutes at 50 Hz; a longer
//! fade takes a `u64` one), none at full or zero gain. `S` is formed from
//! 16-bit halves: `x² = qₕ·2¹⁶ + qₗ`, `c = 3·2¹⁶ − 2x = cₕ·2¹⁶ + cₗ`,
//! `⌊x²c/2³²⌋ = ⌊(qₕc + qₗcₕ + ⌊qₗcₗ/2¹⁶⌋)/2¹⁶⌋`. Every partial sum is at most
//! `x²c/2¹⁶ = 2³²·S(x/2¹⁶) < 2³²` for `x < 2¹⁶`: `u32` throughout.

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
}

impl Envelope {
    /// An envelope at zero gain, about to fade in over `frames` frames.
    pub(crate) const fn new(frames: u32) -> Self {
        Self {
            frames,
            level: 0,
            stopping: false,
        }
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
        let x = if self.frames <= UNITY {
            match (self.level << 16).checked_div(self.frames) {
                Some(x) => x,
                None => 0,
            }
        } else {
            match ((self.level as u64) << 16).checked_div(self.frames as u64) {
                Some(x) => x as u32,
                None => 0,
            }
        };
        smoothstep(x)
    }

    /// Moves one frame along the ramp.
    pub(crate) const fn advance(&mut self) {
        if self.stopping {
            self.level = self.level.saturating_sub(1);
        } else if self.level < self.frames {
            self.level += 1;
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
