//! The mixer's per-frame arithmetic: Q16 gains and ducks, the gesture
//! layers' sums, and the countdown behind each axis' limit mode.

use super::super::fixed::{ONE, mul};
use super::super::params::LimitMode;

/// The gesture layers of one frame, per axis `[pitch, roll, yaw]`.
pub(super) struct Sums {
    /// The gestures' offsets, m°.
    pub(super) add: [i32; 3],
    /// The idle's duck, Q16.
    pub(super) duck: [u32; 3],
    /// Bit `i`: a gesture plays on axis `i`.
    pub(super) active: u8,
}

impl Sums {
    /// No gesture: nothing added, no duck.
    pub(super) const NONE: Self = Self {
        add: [0; 3],
        duck: [ONE; 3],
        active: 0,
    };
}

/// The idle kept on a look's axes at envelope `envelope` (Q16, taken
/// within `0..=1`): `1 − duck · envelope` (1 without a look, one
/// subtraction while it holds).
#[inline]
pub(super) const fn look_keep(duck: u32, envelope: i32) -> u32 {
    if envelope <= 0 {
        ONE
    } else if envelope >= ONE as i32 {
        ONE - duck
    } else {
        ONE - mul(duck as i32, envelope as u32) as u32
    }
}

/// The product of two Q16 fractions (a factor of 1 skipped).
#[inline]
pub(super) const fn both(a: u32, b: u32) -> u32 {
    if b == ONE {
        a
    } else if a == ONE {
        b
    } else {
        mul(a as i32, b) as u32
    }
}

/// `idle · gain · duck` (Q16 each; a factor of 1 skipped: `mul` by 1 is
/// exact).
#[inline]
pub(super) const fn idle_part(idle: i32, gain: u32, duck: u32) -> i32 {
    let value = if gain == ONE { idle } else { mul(idle, gain) };
    if duck == ONE { value } else { mul(value, duck) }
}

/// What the limit modes of one frame mixed in full follow from (see
/// [`Mixer::events`](super::Mixer)).
pub(super) struct Countdown {
    /// Bit `i`: axis `i` is on at this frame.
    pub(super) on: u8,
    /// Bit `i`: axis `i` was on at the last frame mixed in full.
    pub(super) was_on: u8,
    /// µs in gesture mode after an axis was last on.
    pub(super) settle: u32,
    /// µs since the last frame mixed, and since the last mixed in full.
    pub(super) since_prev: u32,
    pub(super) since_full: u32,
}

impl Countdown {
    /// Axis `i`'s limit mode from the next frame on, its time `left` in
    /// gesture mode updated: gesture while on (and `settle` after) or when a
    /// return starts (`soon`). An axis off but still settling lowers
    /// `soonest` to the time until it settles.
    #[inline]
    pub(super) fn mode(&self, i: u32, left: &mut u32, soon: bool, soonest: &mut u32) -> LimitMode {
        let bit = 1 << i;
        if self.on & bit != 0 {
            *left = self.settle;
            return LimitMode::Gesture;
        }
        // Off since the last frame (on until then), or since the last frame
        // mixed in full: gesture mode counts down by the time passed.
        *left = if self.was_on & bit != 0 {
            self.settle.saturating_sub(self.since_prev)
        } else {
            left.saturating_sub(self.since_full)
        };
        if *left > 0 {
            *soonest = (*soonest).min(*left);
            LimitMode::Gesture
        } else if soon {
            LimitMode::Gesture
        } else {
            LimitMode::Idle
        }
    }
}
