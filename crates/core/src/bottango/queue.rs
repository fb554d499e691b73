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

    /// Registers `axis` as a motor whose signal runs from `min` (movement 0)
    /// to `max` (full movement), m°.
    ///
    /// # Errors
    /// [`MotorError::Registered`] if it is already.
    pub fn register(&self, axis: Axis, min: i32, max: i32) -> Result<(), MotorError> {
        self.motor(axis, |m| {
            if m.registered {
                return Err(MotorError::Registered);
            }
            *m = Motor {
                registered: true,
                bounds: (min, max),
                ..Motor::EMPTY
            };
            Ok(())
        })
        .unwrap_or(Err(MotorError::NotRegistered))
    }

    /// New signal bounds for `axis`.
    ///
    /// # Errors
    /// [`MotorError::NotRegistered`].
    pub fn set_bounds(&self, axis: Axis, min: i32, max: i32) -> Result<(), MotorError> {
        self.registered(axis, |m| m.bounds = (min, max))
    }

    /// Runs `f` on `axis`' motor if it is registered.
    fn registered(&self, axis: Axis, f: impl FnOnce(&mut Motor)) -> Result<(), MotorError> {
        self.motor(axis, |m| {
            if m.registered {
                f(m);
                Ok(())
            } else {
                Err(MotorError::NotRegistered)
            }
        })
        .unwrap_or(Err(MotorError::NotRegistered))
    }

    /// Deregisters `axis`.
    ///
    /// # Errors
    /// [`MotorError::NotRegistered`].
    pub fn deregister(&self, axis: Axis) -> Result<(), MotorError> {
        self.registered(axis, |m| *m = Motor::EMPTY)
    }

    /// Deregisters every motor.
    pub fn deregister_all(&self) {
        self.with(|motors| *motors = [Motor::EMPTY; 3]);
    }

    /// Drops `axis`' curves (its position is held).
    ///
    /// # Errors
    /// [`MotorError::NotRegistered`].
    pub fn clear(&self, axis: Axis) -> Result<(), MotorError> {
        self.registered(axis, |m| m.valid = 0)
    }

    /// Drops every motor's curves.
    pub fn clear_all(&self) {
        self.with(|motors| {
            for m in motors {
                m.valid = 0;
            }
        });
    }

    /// Adds `curve` to `axis`' motor, over its oldest if it has
    /// [`DEPTH`] already.
    ///
    /// # Errors
    /// [`MotorError::NotRegistered`].
    pub fn push(&self, axis: Axis, curve: Curve) -> Result<(), MotorError> {
        self.registered(axis, |m| {
            let i = usize::from(m.next) % DEPTH;
            if let Some(slot) = m.curves.get_mut(i) {
                *slot = curve;
            }
            m.valid |= 1 << i;
            m.next = ((i + 1) % DEPTH) as u8;
        })
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
        curves.register(Axis::Yaw, -23_000, 32_000).unwrap();
        assert_eq!(
            curves.register(Axis::Yaw, 0, 1),
            Err(MotorError::Registered)
        );
        assert_eq!(
            curves.push(Axis::Pitch, ramp(0, 10, 0, 1)),
            Err(MotorError::NotRegistered)
        );
        // Nothing yet: no position, nothing plays.
        assert_eq!(curves.sample(0), Some(Sample::default()));
        curves.push(Axis::Yaw, ramp(100, 1000, 0, 8192)).unwrap();
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
        curves.push(Axis::Yaw, ramp(5010, 20, 8192, 4096)).unwrap();
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
        curves.register(Axis::Pitch, 0, 8192).unwrap();
        for k in 0..6 {
            curves
                .push(
                    Axis::Pitch,
                    ramp(k * 100, 100, 1000 * k as i32, 1000 * k as i32),
                )
                .unwrap();
        }
        // The first two were overwritten: at 50 nothing plays yet.
        assert!(curves.sample(50).unwrap().axes == 0);
        assert_eq!(curves.sample(250).unwrap().angles[0], 2000);
        // Overlapping: the hold started last plays.
        curves.push(Axis::Pitch, Curve::hold(260, 7000)).unwrap();
        assert_eq!(curves.sample(270).unwrap().angles[0], 7000);
        curves.clear(Axis::Pitch).unwrap();
        let cleared = curves.sample(280).unwrap();
        assert_eq!((cleared.angles[0], cleared.playing), (7000, false));
    }
}
