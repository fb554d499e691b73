//! Fade envelope: smoothstep gain that fades the idle motion in and out.

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
        if self.frames == 0 {
            return if self.stopping { 0 } else { UNITY };
        }
        // x = level / frames in Q16; x ≤ 2^16.
        let x = (self.level as u64 * UNITY as u64) / self.frames as u64;
        // smoothstep: x²(3 − 2x); x² ≤ 2^32, (3 − 2x) ≤ 3·2^16: product < 2^50.
        let s = (x * x * (3 * UNITY as u64 - 2 * x)) >> 32;
        if s > UNITY as u64 { UNITY } else { s as u32 }
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
