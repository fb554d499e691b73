//! Idle-loop motion generation (Kocoń, section 3), computed once at boot.
//!
//! Per axis: the paper's LCG drives a ±δ random walk of N samples, a Hann window
//! of W taps smooths it, the result is scaled into [α1, α2] degrees, and the
//! loop is closed so that it starts at zero (the neutral pose) and repeats with
//! no jump. Two closures are available ([`Closure`]):
//!
//! - [`Closure::Seamless`] (default): the walk is made periodic (its mean step
//!   is removed) and smoothed *circularly*, so the loop is as smooth across its
//!   seam as everywhere else and equally lively along its whole length; it is
//!   then started at a crossing of the neutral pose.
//! - [`Closure::Paper`]: the paper's Figure 6 — causal smoothing, normalisation
//!   to exactly [α1, α2], a length-N Hann taper that brings both ends to zero,
//!   and an exchange of the two halves at a zero crossing drawn from the LCG.
//!
//! Everything is integer arithmetic, identical on host and target, with no
//! allocation; the smoother costs O(N) whatever W is (see `engine.rs`).

mod engine;
mod kernel;
mod lcg;
mod storage;

pub use engine::{LoopInfo, Trace};
pub use kernel::{HannKernel, MAX_WINDOW, MIN_WINDOW};
pub use lcg::{A as LCG_A, C as LCG_C, Lcg, step_of};
pub use storage::{FINE_PER_MDEG, Fnv1a, LoopScale, Mdeg16, Q16, Sample};

use crate::axis::Axis;
use crate::units::{Angle, AngleRange};

/// Samples per loop of the paper's examples (Table 2).
pub const DEFAULT_N: usize = 900;
/// Smallest loop length (samples).
pub const MIN_N: usize = 16;
/// Largest loop length (samples); keeps every intermediate sum inside `i32`.
pub const MAX_N: usize = 8192;
/// Largest walk step δ.
pub const MAX_STEP: Angle = Angle::from_degrees(90);

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
    /// The first [`MotionError`] found, in the order N, W, δ, range.
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
        if r.min.millidegrees() < i16::MIN as i32 + 1 || r.max.millidegrees() > i16::MAX as i32 {
            return Err(MotionError::StorageOverflow { range: r });
        }
        if !axis.anatomical_limits().contains_range(&r) {
            return Err(MotionError::RangeOutsideLimits {
                axis,
                range: r,
                limits: axis.anatomical_limits(),
            });
        }
        if r.min.millidegrees() >= 0 || r.max.millidegrees() <= 0 {
            return Err(MotionError::RangeExcludesNeutral { range: r });
        }
        Ok(())
    }
}

/// A rejected motion parameter, handing back what was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum MotionError {
    /// N is below [`MIN_N`].
    LengthTooShort {
        /// The rejected length.
        n: usize,
        /// The smallest allowed.
        min: usize,
    },
    /// N is above [`MAX_N`].
    LengthTooLong {
        /// The rejected length.
        n: usize,
        /// The largest allowed.
        max: usize,
    },
    /// W is below [`MIN_WINDOW`].
    WindowTooSmall {
        /// The rejected window.
        window: u16,
        /// The smallest allowed.
        min: u16,
    },
    /// W is above N/2 (so in particular W ≥ N) or above [`MAX_WINDOW`].
    WindowTooLarge {
        /// The rejected window.
        window: u16,
        /// The largest allowed for this N.
        max: u16,
    },
    /// δ is zero or negative.
    StepNotPositive {
        /// The rejected step.
        step: Angle,
    },
    /// δ is above [`MAX_STEP`].
    StepTooLarge {
        /// The rejected step.
        step: Angle,
        /// The largest allowed.
        max: Angle,
    },
    /// α1 ≥ α2.
    RangeInverted {
        /// The rejected range.
        range: AngleRange,
    },
    /// The range does not contain the neutral pose (0°) strictly inside, so
    /// no loop that starts at zero can fill it.
    RangeExcludesNeutral {
        /// The rejected range.
        range: AngleRange,
    },
    /// The range leaves the axis' anatomical limits (paper, Table 1).
    RangeOutsideLimits {
        /// The axis.
        axis: Axis,
        /// The rejected range.
        range: AngleRange,
        /// The axis' limits.
        limits: AngleRange,
    },
    /// The range does not fit the `i16` millidegree storage (±32.767°).
    StorageOverflow {
        /// The rejected range.
        range: AngleRange,
    },
    /// The smoothed walk of this seed is (nearly) flat: there is no motion to
    /// scale into the range.
    Degenerate {
        /// The seed.
        seed: u32,
    },
}

impl MotionError {
    /// A one-line description naming the offending field.
    #[must_use]
    pub const fn message(&self) -> &'static str {
        match self {
            MotionError::LengthTooShort { .. } => "N (samples per loop) is below MIN_N (16)",
            MotionError::LengthTooLong { .. } => "N (samples per loop) is above MAX_N (8192)",
            MotionError::WindowTooSmall { .. } => "window (W) must be at least 3 taps",
            MotionError::WindowTooLarge { .. } => {
                "window (W) must be at most N/2 and at most 511 taps"
            }
            MotionError::StepNotPositive { .. } => "step (delta) must be positive",
            MotionError::StepTooLarge { .. } => "step (delta) must be at most 90 degrees",
            MotionError::RangeInverted { .. } => "range: min (alpha1) must be below max (alpha2)",
            MotionError::RangeExcludesNeutral { .. } => {
                "range: must contain 0 (the neutral pose) strictly inside"
            }
            MotionError::RangeOutsideLimits { .. } => {
                "range: must lie within the axis' anatomical limits (Table 1)"
            }
            MotionError::StorageOverflow { .. } => {
                "range: does not fit i16 millidegree storage (+-32.767 degrees)"
            }
            MotionError::Degenerate { .. } => "seed: the smoothed walk is flat, no motion to scale",
        }
    }
}

impl core::fmt::Display for MotionError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}: {:?}", self.message(), self)
    }
}

impl core::error::Error for MotionError {}

/// A motion error together with the axis it concerns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisError {
    /// The axis whose configuration was rejected.
    pub axis: Axis,
    /// What was wrong.
    pub error: MotionError,
}

impl core::fmt::Display for AxisError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}: {}", self.axis.name(), self.error)
    }
}

impl core::error::Error for AxisError {}

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

    /// The same configuration with every axis on `closure`.
    #[must_use]
    pub const fn with_closure(mut self, closure: Closure) -> Self {
        self.pitch.closure = closure;
        self.roll.closure = closure;
        self.yaw.closure = closure;
        self
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
    /// use idle_head::motion::{DEFAULT_HEAD, HeadConfig};
    /// const BAD: HeadConfig = HeadConfig { pitch: DEFAULT_HEAD.pitch.with_window(2), ..DEFAULT_HEAD };
    /// const _: () = BAD.assert_valid(900);
    /// ```
    pub const fn assert_valid(&self, n: usize) {
        if let Err(e) = self.validate(n) {
            match e.axis {
                Axis::Pitch => panic!("{}", concat_axis::PITCH[e.error.index()]),
                Axis::Roll => panic!("{}", concat_axis::ROLL[e.error.index()]),
                Axis::Yaw => panic!("{}", concat_axis::YAW[e.error.index()]),
            }
        }
    }
}

impl AxisConfig {
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

impl MotionError {
    const fn index(&self) -> usize {
        match self {
            MotionError::LengthTooShort { .. } => 0,
            MotionError::LengthTooLong { .. } => 1,
            MotionError::WindowTooSmall { .. } => 2,
            MotionError::WindowTooLarge { .. } => 3,
            MotionError::StepNotPositive { .. } => 4,
            MotionError::StepTooLarge { .. } => 5,
            MotionError::RangeInverted { .. } => 6,
            MotionError::RangeExcludesNeutral { .. } => 7,
            MotionError::RangeOutsideLimits { .. } => 8,
            MotionError::StorageOverflow { .. } => 9,
            MotionError::Degenerate { .. } => 10,
        }
    }
}

/// Compile-time messages: `"<axis>: <field message>"` for every axis and error.
mod concat_axis {
    macro_rules! messages {
        ($axis:literal) => {
            [
                concat!($axis, ": N (samples per loop) is below MIN_N (16)"),
                concat!($axis, ": N (samples per loop) is above MAX_N (8192)"),
                concat!($axis, ": window (W) must be at least 3 taps"),
                concat!(
                    $axis,
                    ": window (W) must be at most N/2 and at most 511 taps"
                ),
                concat!($axis, ": step (delta) must be positive"),
                concat!($axis, ": step (delta) must be at most 90 degrees"),
                concat!($axis, ": range: min (alpha1) must be below max (alpha2)"),
                concat!(
                    $axis,
                    ": range: must contain 0 (the neutral pose) strictly inside"
                ),
                concat!(
                    $axis,
                    ": range: must lie within the axis' anatomical limits (Table 1)"
                ),
                concat!(
                    $axis,
                    ": range: does not fit i16 millidegree storage (+-32.767 degrees)"
                ),
                concat!(
                    $axis,
                    ": seed: the smoothed walk is flat, no motion to scale"
                ),
            ]
        };
    }
    pub(super) const PITCH: [&str; 11] = messages!("pitch");
    pub(super) const ROLL: [&str; 11] = messages!("roll");
    pub(super) const YAW: [&str; 11] = messages!("yaw");
}

/// The paper's Table 2 example set, one row per axis of the chain
/// (C1 pitch, C2 roll, C3 yaw), N = 900, W = 59, with the seamless closure.
pub const DEFAULT_HEAD: HeadConfig = HeadConfig {
    pitch: AxisConfig::paper_row(127, 59, -4, 12),
    roll: AxisConfig::paper_row(259, 59, -13, 13),
    yaw: AxisConfig::paper_row(8821, 59, -9, 9),
};
const _: () = DEFAULT_HEAD.assert_valid(DEFAULT_N);

/// One axis' loop of `N` samples, usable in a `static`.
#[derive(Clone, Debug)]
pub struct Trajectory<S: Sample, const N: usize> {
    samples: [S; N],
    /// Where playback starts in `samples` (the loop is stored as a ring).
    start: u16,
    /// How `samples` map to angles: [`LoopScale::NEUTRAL`] before a loop is
    /// generated, the loop's own scale for [`Q16`], else [`LoopScale::MDEG`].
    scale: LoopScale,
}

impl<S: Sample, const N: usize> Trajectory<S, N> {
    /// Samples per loop.
    pub const LEN: usize = N;

    /// An all-zero loop (the neutral pose); fill it with [`Trajectory::generate`].
    #[must_use]
    pub const fn new() -> Self {
        const {
            assert!(
                N >= MIN_N && N <= MAX_N,
                "Trajectory length N must be in MIN_N..=MAX_N"
            );
        };
        Self {
            samples: [S::ZERO; N],
            start: 0,
            scale: LoopScale::NEUTRAL,
        }
    }

    /// Computes the loop for `cfg` on `axis`, with `kernel` built for `cfg.window`.
    ///
    /// # Errors
    /// Any [`MotionError`] of [`AxisConfig::validate`], or [`MotionError::Degenerate`].
    /// On error the loop is left all zero (the neutral pose).
    pub fn generate(
        &mut self,
        cfg: &AxisConfig,
        axis: Axis,
        kernel: &HannKernel,
    ) -> Result<LoopInfo, MotionError> {
        self.generate_traced(cfg, axis, kernel, &mut ())
    }

    /// [`Trajectory::generate`], reporting intermediate stages to `trace`
    /// (previews, tests); `&mut ()` traces nothing and costs nothing.
    ///
    /// # Errors
    /// As [`Trajectory::generate`].
    pub fn generate_traced<T: Trace>(
        &mut self,
        cfg: &AxisConfig,
        axis: Axis,
        kernel: &HannKernel,
        trace: &mut T,
    ) -> Result<LoopInfo, MotionError> {
        self.generate_checked(cfg.validate(axis, N), cfg, kernel, trace)
    }

    /// Generates from `cfg` if `checked` (its validation, done by the
    /// caller) passed, and keeps the ring as computed: no rotation.
    fn generate_checked<T: Trace>(
        &mut self,
        checked: Result<(), MotionError>,
        cfg: &AxisConfig,
        kernel: &HannKernel,
        trace: &mut T,
    ) -> Result<LoopInfo, MotionError> {
        self.start = 0;
        self.scale = LoopScale::NEUTRAL;
        let result = checked.and_then(|()| engine::generate(&mut self.samples, cfg, kernel, trace));
        match result {
            Ok((info, scale)) => {
                self.start = info.start;
                if S::KEEPS_SCALE {
                    self.scale = scale;
                } else {
                    engine::finalise(&mut self.samples, &scale);
                    self.scale = LoopScale::MDEG;
                }
                Ok(info)
            }
            Err(e) => {
                self.samples = [S::ZERO; N];
                Err(e)
            }
        }
    }

    /// The stored samples, a ring: playback starts at [`Trajectory::start`].
    #[must_use]
    pub const fn samples(&self) -> &[S; N] {
        &self.samples
    }

    /// Where playback starts in [`Trajectory::samples`].
    #[must_use]
    pub const fn start(&self) -> usize {
        self.start as usize
    }

    /// How [`Trajectory::samples`] map to angles: the loop's own scale for
    /// [`Q16`], [`LoopScale::MDEG`] for the other storages
    /// ([`LoopScale::NEUTRAL`] until a loop is generated).
    #[must_use]
    pub const fn scale(&self) -> &LoopScale {
        &self.scale
    }

    /// The samples in playback order; the first is the neutral pose.
    pub fn playback(&self) -> impl Iterator<Item = &S> + '_ {
        let (head, tail) = self.samples.split_at(self.start().min(N));
        tail.iter().chain(head)
    }

    /// Sample `index` of the loop in playback order (taken modulo N) as an angle.
    #[must_use]
    pub fn angle(&self, index: usize) -> Angle {
        let mut i = self.start() + index % N;
        if i >= N {
            i -= N;
        }
        self.samples
            .get(i)
            .map_or(Angle::ZERO, |s| s.angle_in(&self.scale))
    }
}

impl<S: Sample, const N: usize> crate::playback::LoopSource for Trajectory<S, N> {
    fn len(&self) -> usize {
        N
    }

    fn angle(&self, index: usize) -> Angle {
        Trajectory::angle(self, index)
    }
}

impl<S: Sample, const N: usize> Default for Trajectory<S, N> {
    fn default() -> Self {
        Self::new()
    }
}

/// Computes one loop into a buffer of any length (N = `out.len()`), for
/// callers that size buffers at run time, and returns it in playback order
/// (index 0 is the neutral pose). [`Trajectory`] keeps const-generic loops as
/// a ring instead and saves the rotation.
///
/// # Errors
/// Any [`MotionError`] of [`AxisConfig::validate`], a kernel built for another
/// window ([`MotionError::WindowTooLarge`]), or [`MotionError::Degenerate`].
/// On error `out` is left all zero (the neutral pose).
pub fn generate_into<S: Sample, T: Trace>(
    out: &mut [S],
    cfg: &AxisConfig,
    axis: Axis,
    kernel: &HannKernel,
    trace: &mut T,
) -> Result<LoopInfo, MotionError> {
    let result = cfg
        .validate(axis, out.len())
        .and_then(|()| engine::generate(out, cfg, kernel, trace));
    match result {
        Ok((mut info, scale)) => {
            // Slices come back finalised (a `Q16` holds millidegrees) and in
            // playback order.
            engine::finalise(out, &scale);
            out.rotate_left(usize::from(info.start));
            info.start = 0;
            Ok(info)
        }
        Err(e) => {
            out.fill(S::ZERO);
            Err(e)
        }
    }
}

/// The three loops of a head (pitch, roll, yaw), usable in a `static`.
#[derive(Clone, Debug)]
pub struct HeadTrajectories<S: Sample, const N: usize> {
    axes: [Trajectory<S, N>; 3],
}

impl<S: Sample, const N: usize> HeadTrajectories<S, N> {
    /// Three all-zero loops.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            axes: [Trajectory::new(), Trajectory::new(), Trajectory::new()],
        }
    }

    /// Computes all three loops; one kernel table is shared by axes with equal W.
    ///
    /// # Errors
    /// The first axis whose configuration is rejected; that axis and the ones
    /// after it are left all zero.
    pub fn generate(&mut self, cfg: &HeadConfig) -> Result<[LoopInfo; 3], AxisError> {
        cfg.validate(N)?;
        let mut infos = [LoopInfo::default(); 3];
        // Built in place, axis by axis (a window equal to the last one's is
        // kept as it is).
        let mut kernel = HannKernel::empty();
        for axis in Axis::ALL {
            let c = cfg.axis(axis);
            kernel
                .rebuild(c.window)
                .map_err(|error| AxisError { axis, error })?;
            let i = axis.index();
            // Validated above, with the other axes.
            infos[i] = self.axes[i]
                .generate_checked(Ok(()), c, &kernel, &mut ())
                .map_err(|error| AxisError { axis, error })?;
        }
        Ok(infos)
    }

    /// The loop of `axis`.
    #[must_use]
    pub const fn axis(&self, axis: Axis) -> &Trajectory<S, N> {
        &self.axes[axis.index()]
    }

    /// FNV-1a over what defines each loop, pitch, roll, yaw: the samples in
    /// playback order, then the loop's scale (little-endian bytes).
    #[must_use]
    pub fn checksum(&self) -> u32 {
        let mut h = Fnv1a::new();
        for t in &self.axes {
            for s in t.playback() {
                s.hash_into(&mut h);
            }
            t.scale.hash_into(&mut h);
        }
        h.finish()
    }
}

impl<S: Sample, const N: usize> Default for HeadTrajectories<S, N> {
    fn default() -> Self {
        Self::new()
    }
}
