//! How a gesture moves: the [`Shape`]s a row of the
//! [gesture table](crate::gestures) can name.
//!
//! A gesture adds `E(φ) · A(φ) · c(φ)` to its axis (see
//! [`gesture`](super::gesture) for the envelope `E` and the profile `A`);
//! the shape gives the carrier `c`, how long the envelope's ramps are, which
//! amplitudes an axis allows, and the bounds of its peak speed and
//! acceleration:
//!
//! | shape | carrier `c(φ)` | ramps | amplitude | `(Kv, Ka)` | gestures |
//! |---|---|---|---|---|---|
//! | [`Dip`](Shape::Dip) | `(1 − cos 2πφ)/2` | ½ cycle | positive, up to the axis' upper limit | (1.45, 1.85), on `A/2` | nod |
//! | [`Swing`](Shape::Swing) | `sin 2πφ` | ½ cycle | positive, up to the nearer limit | (1.05, 1.65) | shake |
//! | [`Lean`](Shape::Lean) | `1` (a posture, one cycle) | ⅓ of it | either sign, within the limits | (0.9, 1.32) | tilt |
//!
//! - **Dip**: each cycle dips towards positive angles and comes back: a
//!   cycle is a down and an up movement and its magnitude is the dip, as
//!   Mori, Den & Jokinen measure nods. The first downstroke is the ramp and
//!   still reaches the full first dip at `φ = ½`.
//! - **Swing**: to either side of the centre.
//! - **Lean**: up over the first third along the envelope, held, down over
//!   the last third; the amplitude's sign chooses the side.
//!
//! **Speed check.** A shape's peak speed and acceleration are at most
//! `Kv·ω·a` and `Ka·ω²·a` (`ω = 2πf`, `a` the carrier's amplitude): measured
//! on the continuous shape over 1 to 32 cycles and rounded up (the
//! envelope's ramps make the first and the last half cycle steeper than the
//! bare carrier).
//!
//! A new shape is a new variant here with an arm in each `match` below, and
//! a row of the gesture table that names it.

use crate::units::{Angle, AngleRange};

use super::fixed::{ONE, mul, mul_signed};

/// How a gesture moves; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Shape {
    /// Dips towards positive angles and back, `n` times (a nod).
    Dip,
    /// Swings to either side of the centre, `n` times (a shake).
    Swing,
    /// Leans to one side, holds, and comes back: one cycle (a tilt).
    Lean,
}

impl Shape {
    /// Whether the shape repeats: a [`Lean`](Self::Lean) has exactly one
    /// cycle.
    #[must_use]
    pub const fn has_cycles(self) -> bool {
        match self {
            Self::Dip | Self::Swing => true,
            Self::Lean => false,
        }
    }

    /// `(Kv, Ka)` in thousandths.
    pub(crate) const fn peak_factors(self) -> (u64, u64) {
        match self {
            Self::Dip => (1450, 1850),
            Self::Swing => (1050, 1650),
            Self::Lean => (900, 1320),
        }
    }

    /// The carrier's amplitude `a` for a first peak `amplitude` (m°).
    pub(crate) const fn carrier(self, amplitude: u64) -> u64 {
        match self {
            Self::Dip => amplitude / 2,
            Self::Swing | Self::Lean => amplitude,
        }
    }

    /// The envelope's ramps last `1/ramp` cycles.
    pub(crate) const fn ramp(self) -> u32 {
        match self {
            Self::Dip | Self::Swing => 2,
            Self::Lean => 3,
        }
    }

    /// The amplitudes allowed on an axis whose offsets may span `room`.
    pub(crate) const fn allowed(self, room: AngleRange) -> AngleRange {
        let positive = Angle::from_millidegrees(1);
        match self {
            Self::Dip => AngleRange {
                min: positive,
                max: room.max,
            },
            Self::Swing => {
                // Both sides: the nearer limit.
                let other = room.min.millidegrees().saturating_neg();
                AngleRange {
                    min: positive,
                    max: if room.max.millidegrees() < other {
                        room.max
                    } else {
                        Angle::from_millidegrees(other)
                    },
                }
            }
            Self::Lean => room,
        }
    }

    /// `scaled · c(φ)` for `phi` = φ in Q16 cycles (`scaled`: the
    /// enveloped amplitude, m°).
    #[inline]
    pub(crate) fn value(self, scaled: i32, phi: u32) -> i32 {
        match self {
            Self::Lean => scaled,
            Self::Dip | Self::Swing => {
                // frac(φ) as a 32-bit phase (2³² = one turn).
                let (cos, sin) = idsp::cossin((phi << 16) as i32);
                if let Self::Dip = self {
                    // (1 − cos)/2 in Q16: cos in Q31 → Q17 halves it.
                    mul(scaled, (ONE as i32 - (cos >> 15)) as u32 >> 1)
                } else {
                    mul_signed(scaled, sin >> 15)
                }
            }
        }
    }
}
