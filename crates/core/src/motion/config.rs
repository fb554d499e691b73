//! What a head's motion is made of: per axis the seed, the window, the step,
//! the range and the closure (the paper's Table 2), and their validation.

use super::error::{AxisError, MotionError};
use super::limits::{MAX_N, MAX_STEP, MAX_WINDOW, MIN_N, MIN_WINDOW};
use super::storage::Mdeg16;
use crate::axis::Axis;
use crate::units::{Angle, AngleRange};

/// Samples per loop of the paper's examples (Table 2).
pub const DEFAULT_N: usize = 900;

/// How the loop is closed so that it starts at zero and repeats seamlessly.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Closure {
    /// The paper's Figure 6: taper with a length-N Hann window, split at a zero
    /// crossing chosen from the LCG stream, exchange the halves.
    Paper,
    /// A periodic walk smoothed circularly: continuous in value, velocity and
    /// acceleration everywhere, lively along its whole length.
    #[default]
    Seamless,
}

/// The parameters of one axis (paper, Table 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisConfig {
    /// LCG seed r(0).
    pub seed: u32,
    /// Hann window length W (taps), `MIN_WINDOW..=min(N/2, MAX_WINDOW)`.
    pub window: u16,
    /// Walk step δ (> 0). The final loop does not depend on it (normalisation
    /// removes the scale); it sets the units of the walk in previews.
    pub step: Angle,
    /// Target range [α1, α2]; must contain the neutral pose strictly inside and
    /// lie within the axis' anatomical limits (Table 1).
    pub range: AngleRange,
    /// Loop closure.
    pub closure: Closure,
}

impl AxisConfig {
    /// One row of the paper's Table 2 (N is the trajectory type's length).
    #[must_use]
    pub const fn paper_row(seed: u32, window: u16, min_deg: i32, max_deg: i32) -> Self {
        Self {
            seed,
            window,
            step: Angle::from_degrees(1),
            range: AngleRange::degrees(min_deg, max_deg),
            closure: Closure::Seamless,
        }
    }

    /// The same configuration with another closure.
    #[must_use]
    pub const fn with_closure(mut self, closure: Closure) -> Self {
        self.closure = closure;
        self
    }

    /// Checks every parameter for a loop of `n` samples on `axis`.
    ///
    /// # Errors
    /// The first [`MotionError`] found, in the order N, W, δ, range (order,
    /// the axis' limits, the storage, the neutral pose).
    pub const fn validate(&self, axis: Axis, n: usize) -> Result<(), MotionError> {
        if n < MIN_N {
            return Err(MotionError::LengthTooShort { n, min: MIN_N });
        }
        if n > MAX_N {
            return Err(MotionError::LengthTooLong { n, max: MAX_N });
        }
        if self.window < MIN_WINDOW {
            return Err(MotionError::WindowTooSmall {
                window: self.window,
                min: MIN_WINDOW,
            });
        }
        let max_w = if n / 2 < MAX_WINDOW as usize {
            (n / 2) as u16
        } else {
            MAX_WINDOW
        };
        if self.window > max_w {
            return Err(MotionError::WindowTooLarge {
                window: self.window,
                max: max_w,
            });
        }
        if self.step.millidegrees() <= 0 {
            return Err(MotionError::StepNotPositive { step: self.step });
        }
        if self.step.millidegrees() > MAX_STEP.millidegrees() {
            return Err(MotionError::StepTooLarge {
                step: self.step,
                max: MAX_STEP,
            });
        }
        let r = self.range;
        if r.min.millidegrees() >= r.max.millidegrees() {
            return Err(MotionError::RangeInverted { range: r });
        }
        if !axis.anatomical_limits().contains_range(&r) {
            return Err(MotionError::RangeOutsideLimits {
                axis,
                range: r,
                limits: axis.anatomical_limits(),
            });
        }
        // Table 1 lies inside the storage; this guards it should the
        // limits ever be widened.
        if !Mdeg16::RANGE.contains_range(&r) {
            return Err(MotionError::StorageOverflow { range: r });
        }
        if r.min.millidegrees() >= 0 || r.max.millidegrees() <= 0 {
            return Err(MotionError::RangeExcludesNeutral { range: r });
        }
        Ok(())
    }

    /// The same configuration with another window (W).
    #[must_use]
    pub const fn with_window(mut self, window: u16) -> Self {
        self.window = window;
        self
    }

    /// The same configuration with another seed.
    #[must_use]
    pub const fn with_seed(mut self, seed: u32) -> Self {
        self.seed = seed;
        self
    }

    /// The same configuration with another range.
    #[must_use]
    pub const fn with_range(mut self, range: AngleRange) -> Self {
        self.range = range;
        self
    }
}

/// The motion parameters of the three axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HeadConfig {
    /// C1, pitch.
    pub pitch: AxisConfig,
    /// C2, roll.
    pub roll: AxisConfig,
    /// C3, yaw.
    pub yaw: AxisConfig,
}

impl HeadConfig {
    /// The configuration of `axis`.
    #[must_use]
    pub const fn axis(&self, axis: Axis) -> &AxisConfig {
        match axis {
            Axis::Pitch => &self.pitch,
            Axis::Roll => &self.roll,
            Axis::Yaw => &self.yaw,
        }
    }

    /// The configuration of `axis`, to change.
    pub const fn axis_mut(&mut self, axis: Axis) -> &mut AxisConfig {
        match axis {
            Axis::Pitch => &mut self.pitch,
            Axis::Roll => &mut self.roll,
            Axis::Yaw => &mut self.yaw,
        }
    }

    /// The same configuration with every axis on `closure`.
    #[must_use]
    pub const fn with_closure(mut self, closure: Closure) -> Self {
        self.pitch.closure = closure;
        self.roll.closure = closure;
        self.yaw.closure = closure;
        self
    }

    /// The longest of the three windows W: the kernel capacity that
    /// generates this configuration ([`HeadTrajectories`](super::HeadTrajectories)).
    #[must_use]
    pub const fn longest_window(&self) -> u16 {
        let (p, r, y) = (self.pitch.window, self.roll.window, self.yaw.window);
        let pr = if p > r { p } else { r };
        if pr > y { pr } else { y }
    }

    /// Checks all three axes for loops of `n` samples.
    ///
    /// # Errors
    /// The first rejected axis (pitch, roll, yaw order) and why.
    pub const fn validate(&self, n: usize) -> Result<(), AxisError> {
        let mut i = 0;
        while i < 3 {
            let axis = Axis::ALL[i];
            if let Err(error) = self.axis(axis).validate(axis, n) {
                return Err(AxisError { axis, error });
            }
            i += 1;
        }
        Ok(())
    }

    /// Fails compilation (in a `const` context) with a message naming the axis
    /// and the field when the configuration is invalid for `n` samples.
    ///
    /// # Panics
    /// When the configuration is invalid — by design, so that a `const`
    /// evaluation fails the build.
    ///
    /// ```compile_fail
    /// use idle_head_core::motion::{DEFAULT_HEAD, HeadConfig};
    /// const BAD: HeadConfig = HeadConfig { pitch: DEFAULT_HEAD.pitch.with_window(2), ..DEFAULT_HEAD };
    /// const _: () = BAD.assert_valid(900);
    /// ```
    pub const fn assert_valid(&self, n: usize) {
        if let Err(e) = self.validate(n) {
            e.panic();
        }
    }
}

/// The paper's Table 2 example set, one row per axis of the chain
/// (C1 pitch, C2 roll, C3 yaw), N = 900, W = 59, with the seamless closure.
pub const DEFAULT_HEAD: HeadConfig = HeadConfig {
    pitch: AxisConfig::paper_row(127, 59, -4, 12),
    roll: AxisConfig::paper_row(259, 59, -13, 13),
    yaw: AxisConfig::paper_row(8821, 59, -9, 9),
};
const _: () = DEFAULT_HEAD.assert_valid(DEFAULT_N);

/// The kernel capacity of the firmware's loops: [`DEFAULT_HEAD`]'s longest
/// window (59 taps). The console changes seeds, never windows, so every
/// loop set the firmware generates fits it; it keeps 9 KB of stack free
/// against [`MAX_WINDOW`](super::MAX_WINDOW).
pub const DEFAULT_WINDOW_CAP: usize = DEFAULT_HEAD.longest_window() as usize;
