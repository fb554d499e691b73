//! The curves of the Bottango session, shared between the console port that
//! speaks the protocol and the frame task that plays them.
//!
//! Per axis: whether Bottango registered it as a custom motor, its signal
//! bounds, and up to [`DEPTH`] curves, overwritten oldest first when more
//! arrive (as Bottango's own driver keeps its pre-cached curves). The frame
//! task samples them once a frame ([`Curves::sample`]); the console side
//! registers, clears and adds. A blocking mutex with a critical section
//! around each short access; the borrow inside is `try_borrow_mut`, which
//! cannot fail under the mutex and has no panic path.

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

use super::curve::{Curve, FULL};
use crate::axis::Axis;

/// Curves kept per motor: what the driver reports to the app as its
/// pre-cache depth.
pub const DEPTH: usize = 4;

/// What to do to a motor ([`Curves::apply`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// Register it, its signal running from `min` (movement 0) to `max`
    /// (full movement), m° of the axis.
    Register {
        /// The signal at movement 0.
        min: i32,
        /// The signal at full movement.
        max: i32,
    },
    /// New signal bounds.
    Bounds {
        /// The signal at movement 0.
        min: i32,
        /// The signal at full movement.
        max: i32,
    },
    /// Deregister it.
    Deregister,
    /// Drop its curves (its position is held).
    Clear,
    /// Add a curve, over the oldest if it has [`DEPTH`] already.
    Push(Curve),
}

/// Why a motor command was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MotorError {
    /// The motor is not registered.
    NotRegistered,
    /// The motor is registered already.
    Registered,
}

/// One axis as a custom motor.
#[derive(Clone, Copy, Debug, Default)]
struct Motor {
    registered: bool,
    /// The signal (m° of the axis) at movement 0 and at full movement.
    bounds: (i32, i32),
    curves: [Curve; DEPTH],
    /// Bit `i`: `curves[i]` holds a curve.
    valid: u8,
    /// Where the next curve goes.
    next: u8,
    /// The movement last played (held between and after curves), once a
    /// curve has started.
    held: Option<i32>,
}

impl Motor {
    const EMPTY: Self = Self {
        registered: false,
        bounds: (0, 0),
        curves: [Curve::EMPTY; DEPTH],
        valid: 0,
        next: 0,
        held: None,
    };

    /// The movement at `now`, and whether a curve plays or is to come.
    fn at(&mut self, now: u32) -> (Option<i32>, bool) {
        let mut current: Option<&Curve> = None;
        let mut ended: Option<&Curve> = None;
        let mut coming = false;
        for (i, curve) in self.curves.iter().enumerate() {
            if self.valid & (1 << i) == 0 {
                continue;
            }
            let since = now.wrapping_sub(curve.start) as i32;
            let left = curve.end().wrapping_sub(now) as i32;
            if since < 0 {
                coming = true;
            } else if left >= 0 {
                // In progress: the one that started last wins.
                if current.is_none_or(|c| curve.start.wrapping_sub(c.start) as i32 > 0) {
                    current = Some(curve);
                }
            } else if ended.is_none_or(|c| curve.end().wrapping_sub(c.end()) as i32 > 0) {
                ended = Some(curve);
            }
        }
        if let Some(curve) = current {
            self.held = Some(curve.at(now.wrapping_sub(curve.start)));
            return (self.held, true);
        }
        if let Some(curve) = ended {
            self.held = Some(curve.end_movement());
        }
        (self.held, coming)
    }

    /// The signal (m°) of `movement`, clamped to the bounds.
    fn signal(&self, movement: i32) -> i32 {
        let (min, max) = self.bounds;
        let m = i64::from(movement.clamp(0, FULL));
        let span = i64::from(max) - i64::from(min);
        // Rounded to the nearest: (span·m + 4096) / 8192, floor division.
        let offset = (span * m + i64::from(FULL / 2)).div_euclid(i64::from(FULL));
        (i64::from(min) + offset).clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
    }
}

/// What the curves say for one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Bit `i`: axis `i` has a position (a curve of it has started).
    pub axes: u8,
    /// The axes' angles `[pitch, roll, yaw]`, m° (the motors' signal).
    pub angles: [i32; 3],
    /// Whether any curve plays now or is still to come.
    pub playing: bool,
}

/// The shared curves; lives in a `static`.
pub struct Curves {
    /// A session speaks the protocol (the frame task's quick test).
    active: AtomicBool,
    /// The frame task's clock at its last frame, ms.
    clock: AtomicU32,
    motors: Mutex<CriticalSectionRawMutex, RefCell<[Motor; 3]>>,
}

impl Curves {
    /// No session, no motor.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            active: AtomicBool::new(false),
            clock: AtomicU32::new(0),
            motors: Mutex::new(RefCell::new([Motor::EMPTY; 3])),
        }
    }

    /// Runs `f` on the motors (never re-entered: none of the callers calls
    /// back in).
    fn with<R>(&self, f: impl FnOnce(&mut [Motor; 3]) -> R) -> Option<R> {
        self.motors
            .lock(|cell| cell.try_borrow_mut().ok().map(|mut motors| f(&mut motors)))
    }

    /// Runs `f` on `axis`' motor.
    fn motor<R>(&self, axis: Axis, f: impl FnOnce(&mut Motor) -> R) -> Option<R> {
        self.with(|motors| motors.get_mut(axis.index()).map(f))
            .flatten()
    }

    /// A session starts (`true`) or ends (`false`: every motor is
    /// deregistered, every curve dropped).
    pub fn set_active(&self, active: bool) {
        if !active {
            self.deregister_all();
        }
        self.active.store(active, Ordering::Release);
    }

    /// Whether a session speaks the protocol.
    pub fn active(&self) -> bool {
        self.active.load(Ordering::Acquire)
    }

    /// The frame task's clock, ms, as of its last frame.
    pub fn clock(&self) -> u32 {
        self.clock.load(Ordering::Acquire)
    }

    /// Carries `op` out on `axis`' motor.
    ///
    /// # Errors
    /// [`MotorError::Registered`] to register a motor that is already,
    /// [`MotorError::NotRegistered`] for anything else on a motor that is
    /// not.
    // One function for every operation: each is a few lines, and one body
    // under one lock takes less flash than one per operation.
    #[inline(never)]
    pub fn apply(&self, axis: Axis, op: Op) -> Result<(), MotorError> {
        self.motor(axis, |m| {
            if let Op::Register { min, max } = op {
                if m.registered {
                    return Err(MotorError::Registered);
                }
                *m = Motor {
                    registered: true,
                    bounds: (min, max),
                    ..Motor::EMPTY
                };
                return Ok(());
            }
            if !m.registered {
                return Err(MotorError::NotRegistered);
            }
            match op {
                Op::Register { .. } => {}
                Op::Bounds { min, max } => m.bounds = (min, max),
                Op::Deregister => *m = Motor::EMPTY,
                Op::Clear => m.valid = 0,
                Op::Push(curve) => {
                    let i = usize::from(m.next) % DEPTH;
                    if let Some(slot) = m.curves.get_mut(i) {
                        *slot = curve;
                    }
                    m.valid |= 1 << i;
                    m.next = ((i + 1) % DEPTH) as u8;
                }
            }
            Ok(())
        })
        .unwrap_or(Err(MotorError::NotRegistered))
    }

    /// Deregisters every motor.
    pub fn deregister_all(&self) {
        self.with(|motors| *motors = [Motor::EMPTY; 3]);
    }

    /// Drops every motor's curves (their positions are held).
    pub fn clear_all(&self) {
        self.with(|motors| {
            for m in motors {
                m.valid = 0;
            }
        });
    }

    /// The frame task, once a frame at `now` ms of its clock: the motors'
    /// positions, or `None` without a session (then nothing is locked).
    pub fn sample(&self, now: u32) -> Option<Sample> {
        self.clock.store(now, Ordering::Release);
        if !self.active() {
            return None;
        }
        self.with(|motors| {
            let mut sample = Sample::default();
            for (i, m) in motors.iter_mut().enumerate() {
                if !m.registered {
                    continue;
                }
                let (movement, playing) = m.at(now);
                sample.playing |= playing;
                if let (Some(movement), Some(angle)) = (movement, sample.angles.get_mut(i)) {
                    *angle = m.signal(movement);
                    sample.axes |= 1 << i;
                }
            }
            sample
        })
    }
}

impl Default for Curves {
    fn default() -> Self {
        Self::new()
    }
}

impl core::fmt::Debug for Curves {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Curves")
            .field("active", &self.active())
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bottango::line::CurveArgs;

    fn ramp(start: u32, duration: u32, from: i32, to: i32) -> Curve {
        Curve::new(
            start,
            &CurveArgs {
                start: 0,
                duration,
                start_y: from,
                start_control: (0, 0),
                end_y: to,
                end_control: (0, 0),
            },
        )
    }

    #[test]
    fn plays_holds_and_maps_to_the_signal() {
        let curves = Curves::new();
        assert_eq!(curves.sample(0), None);
        curves.set_active(true);
        curves
            .apply(
                Axis::Yaw,
                Op::Register {
                    min: -23_000,
                    max: 32_000,
                },
            )
            .unwrap();
        assert_eq!(
            curves.apply(Axis::Yaw, Op::Register { min: 0, max: 1 }),
            Err(MotorError::Registered)
        );
        assert_eq!(
            curves.apply(Axis::Pitch, Op::Push(ramp(0, 10, 0, 1))),
            Err(MotorError::NotRegistered)
        );
        // Nothing yet: no position, nothing plays.
        assert_eq!(curves.sample(0), Some(Sample::default()));
        curves
            .apply(Axis::Yaw, Op::Push(ramp(100, 1000, 0, 8192)))
            .unwrap();
        let before = curves.sample(50).unwrap();
        assert_eq!((before.axes, before.playing), (0, true));
        let start = curves.sample(100).unwrap();
        assert_eq!(
            (start.axes, start.angles[2], start.playing),
            (0b100, -23_000, true)
        );
        assert_eq!(curves.sample(1100).unwrap().angles[2], 32_000);
        // Past the end: held, no longer playing.
        let after = curves.sample(5000).unwrap();
        assert_eq!(
            (after.axes, after.angles[2], after.playing),
            (0b100, 32_000, false)
        );
        // An end that falls between two samples is still reached.
        curves
            .apply(Axis::Yaw, Op::Push(ramp(5010, 20, 8192, 4096)))
            .unwrap();
        assert!(curves.sample(5015).unwrap().playing);
        let past = curves.sample(5100).unwrap();
        assert_eq!((past.angles[2], past.playing), (4500, false));
        curves.set_active(false);
        assert_eq!(curves.sample(6000), None);
        curves.set_active(true);
        assert_eq!(curves.sample(6000), Some(Sample::default()));
    }

    #[test]
    fn keeps_the_newest_curves_and_the_latest_start_wins() {
        let curves = Curves::new();
        curves.set_active(true);
        curves
            .apply(Axis::Pitch, Op::Register { min: 0, max: 8192 })
            .unwrap();
        for k in 0..6 {
            let curve = ramp(k * 100, 100, 1000 * k as i32, 1000 * k as i32);
            curves.apply(Axis::Pitch, Op::Push(curve)).unwrap();
        }
        // The first two were overwritten: at 50 nothing plays yet.
        assert!(curves.sample(50).unwrap().axes == 0);
        assert_eq!(curves.sample(250).unwrap().angles[0], 2000);
        // Overlapping: the hold started last plays.
        curves
            .apply(Axis::Pitch, Op::Push(Curve::hold(260, 7000)))
            .unwrap();
        assert_eq!(curves.sample(270).unwrap().angles[0], 7000);
        curves.apply(Axis::Pitch, Op::Clear).unwrap();
        let cleared = curves.sample(280).unwrap();
        assert_eq!((cleared.angles[0], cleared.playing), (7000, false));
    }
}
