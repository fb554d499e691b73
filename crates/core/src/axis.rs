//! The three rotation axes of the head and their anatomical limits.

use crate::units::AngleRange;

/// One rotation axis of the paper's kinematic chain (Figure 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Axis {
    /// C1: nodding (rotation about the ear-to-ear axis).
    Pitch,
    /// C2: tilting (rotation about the front-to-back axis).
    Roll,
    /// C3: turning (rotation about the vertical axis).
    Yaw,
}

impl Axis {
    /// The three axes in the paper's chain order (C1, C2, C3).
    pub const ALL: [Axis; 3] = [Axis::Pitch, Axis::Roll, Axis::Yaw];

    /// Index of the axis in `[pitch, roll, yaw]` arrays.
    #[must_use]
    pub const fn index(self) -> usize {
        match self {
            Axis::Pitch => 0,
            Axis::Roll => 1,
            Axis::Yaw => 2,
        }
    }

    /// Lower-case name, for logs and file names.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Axis::Pitch => "pitch",
            Axis::Roll => "roll",
            Axis::Yaw => "yaw",
        }
    }

    /// The paper's Table 1: ranges of human head motion while waiting, in degrees.
    ///
    /// | axis  | min | max |
    /// |-------|-----|-----|
    /// | roll  | −14 | 19  |
    /// | pitch | −12 | 20  |
    /// | yaw   | −23 | 32  |
    #[must_use]
    pub const fn anatomical_limits(self) -> AngleRange {
        match self {
            Axis::Pitch => AngleRange::degrees(-12, 20),
            Axis::Roll => AngleRange::degrees(-14, 19),
            Axis::Yaw => AngleRange::degrees(-23, 32),
        }
    }
}
