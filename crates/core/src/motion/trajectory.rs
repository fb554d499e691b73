//! The loops as the firmware keeps them: one axis' loop ([`Trajectory`]), a
//! head's three ([`HeadTrajectories`]), and loops of a length chosen at run
//! time ([`generate_into`]).

use super::engine::{self, LoopInfo, Trace};
use super::kernel::HannKernel;
use super::limits::MAX_WINDOW;
use super::storage::{Fnv1a, LoopScale, Sample};
use super::{AxisConfig, AxisError, HeadConfig, MAX_N, MIN_N, MotionError};
use crate::axis::Axis;
use crate::units::Angle;

/// One axis' loop of `N` samples, usable in a `static`.
#[derive(Clone, Debug)]
pub struct Trajectory<S: Sample, const N: usize> {
    samples: [S; N],
    /// Where playback starts in `samples` (the loop is stored as a ring).
    start: u16,
    /// How `samples` map to angles: [`LoopScale::NEUTRAL`] before a loop is
    /// generated, the loop's own scale for [`Integral16`](super::Integral16), else [`LoopScale::MDEG`].
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
    pub fn generate<const CAP: usize>(
        &mut self,
        cfg: &AxisConfig,
        axis: Axis,
        kernel: &HannKernel<CAP>,
    ) -> Result<LoopInfo, MotionError> {
        self.generate_traced(cfg, axis, kernel, &mut ())
    }

    /// [`Trajectory::generate`], reporting intermediate stages to `trace`
    /// (previews, tests); `&mut ()` traces nothing and costs nothing.
    ///
    /// # Errors
    /// As [`Trajectory::generate`].
    pub fn generate_traced<T: Trace, const CAP: usize>(
        &mut self,
        cfg: &AxisConfig,
        axis: Axis,
        kernel: &HannKernel<CAP>,
        trace: &mut T,
    ) -> Result<LoopInfo, MotionError> {
        self.generate_checked(cfg.validate(axis, N), cfg, kernel, trace)
    }

    /// Generates from `cfg` if `checked` (its validation, done by the
    /// caller) passed, and keeps the ring as computed: no rotation.
    fn generate_checked<T: Trace, const CAP: usize>(
        &mut self,
        checked: Result<(), MotionError>,
        cfg: &AxisConfig,
        kernel: &HannKernel<CAP>,
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

    /// Makes playback start at `start` (taken modulo N) in
    /// [`Trajectory::samples`]: the loop is a ring, so it may be entered
    /// anywhere (a never-repeating stream enters each new loop where it
    /// joins the last one best, see `idle`).
    pub fn set_start(&mut self, start: usize) {
        self.start = (start % N) as u16;
    }

    /// How [`Trajectory::samples`] map to angles: the loop's own scale for
    /// [`Integral16`](super::Integral16), [`LoopScale::MDEG`] for the other storages
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
        self.read(index)
    }

    /// [`Trajectory::angle`], inlined where the frame path reads samples
    /// (through [`LoopSource`](crate::playback::LoopSource)).
    #[inline]
    fn read(&self, index: usize) -> Angle {
        // Playback reads indices below N: no division for them (out of
        // line, or the compiler divides before it compares).
        let index = if index < N {
            index
        } else {
            wrap_index::<N>(index)
        };
        let mut i = self.start() + index;
        if i >= N {
            i -= N;
        }
        self.samples
            .get(i)
            .map_or(Angle::ZERO, |s| s.angle_in(&self.scale))
    }
}

/// `index mod N`, for the indices past the loop.
#[cold]
#[inline(never)]
const fn wrap_index<const N: usize>(index: usize) -> usize {
    match index.checked_rem(N) {
        Some(i) => i,
        None => 0,
    }
}

impl<S: Sample, const N: usize> crate::playback::LoopSource for Trajectory<S, N> {
    fn len(&self) -> usize {
        N
    }

    #[inline]
    fn angle(&self, index: usize) -> Angle {
        self.read(index)
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
pub fn generate_into<S: Sample, T: Trace, const CAP: usize>(
    out: &mut [S],
    cfg: &AxisConfig,
    axis: Axis,
    kernel: &HannKernel<CAP>,
    trace: &mut T,
) -> Result<LoopInfo, MotionError> {
    let result = cfg
        .validate(axis, out.len())
        .and_then(|()| engine::generate(out, cfg, kernel, trace));
    match result {
        Ok((mut info, scale)) => {
            // Slices come back finalised (an `Integral16` holds millidegrees) and in
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
///
/// `CAP` is the longest window (W) [`HeadTrajectories::generate`] takes,
/// [`MAX_WINDOW`] unless told otherwise; a longer one is
/// [`MotionError::WindowTooLarge`]. It costs no RAM of its own, but while
/// the loops are computed the smoother keeps `20·CAP` bytes on the stack
/// (its kernel table and tap ring, [`HannKernel`]): about 10 KB for
/// [`MAX_WINDOW`], 1.2 KB for the default set's W = 59.
#[derive(Clone, Debug)]
pub struct HeadTrajectories<S: Sample, const N: usize, const CAP: usize = { MAX_WINDOW as usize }> {
    axes: [Trajectory<S, N>; 3],
}

impl<S: Sample, const N: usize, const CAP: usize> HeadTrajectories<S, N, CAP> {
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
    /// The first axis whose configuration is rejected, or whose window is
    /// longer than `CAP`; that axis and the ones after it are left all zero.
    pub fn generate(&mut self, cfg: &HeadConfig) -> Result<[LoopInfo; 3], AxisError> {
        cfg.validate(N)?;
        let mut infos = [LoopInfo::default(); 3];
        // Built in place, axis by axis (a window equal to the last one's is
        // kept as it is).
        let mut kernel = HannKernel::<CAP>::empty();
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

    /// Computes the loop of `axis` alone from `cfg` (the other axes are left
    /// as they are).
    ///
    /// # Errors
    /// As [`HeadTrajectories::generate`], for this axis; the axis is then
    /// left all zero.
    pub fn generate_axis(&mut self, cfg: &HeadConfig, axis: Axis) -> Result<LoopInfo, AxisError> {
        let c = cfg.axis(axis);
        let mut kernel = HannKernel::<CAP>::empty();
        let checked = c.validate(axis, N).and_then(|()| kernel.rebuild(c.window));
        self.axes[axis.index()]
            .generate_checked(checked, c, &kernel, &mut ())
            .map_err(|error| AxisError { axis, error })
    }

    /// The loop of `axis`.
    #[must_use]
    pub const fn axis(&self, axis: Axis) -> &Trajectory<S, N> {
        &self.axes[axis.index()]
    }

    /// The loops `[pitch, roll, yaw]`.
    #[must_use]
    pub const fn axes(&self) -> &[Trajectory<S, N>; 3] {
        &self.axes
    }

    /// Makes playback of `axis` start at `start` ([`Trajectory::set_start`]).
    pub fn set_start(&mut self, axis: Axis, start: usize) {
        self.axes[axis.index()].set_start(start);
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

impl<S: Sample, const N: usize, const CAP: usize> Default for HeadTrajectories<S, N, CAP> {
    fn default() -> Self {
        Self::new()
    }
}
