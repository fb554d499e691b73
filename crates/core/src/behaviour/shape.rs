//! How a gesture moves: the [`Shape`]s a row of the
//! [gesture table](crate::gestures) can name.
//!
//! A shape gives a gesture's carrier (a dip, a swing, a lean), the length
//! of its envelope's ramps, the amplitudes an axis allows, and the bounds
//! `(Kv, Ka)` of its peak speed and acceleration that the plan checks. A new
//! shape is a new variant here with an arm in each `match` below, and a row
//! of the gesture table that names it.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Gesture shapes”).

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
