//! [`BehaviourParams`]: a validated [`BehaviourConfig`] in the integer
//! form the frame path uses (built by [`BehaviourConfig::build`]), and the
//! [`LimitMode`]s an axis is driven with.

use crate::axis::Axis;
use crate::driver::{MotionLimits, SlewRates, slew_rates};
use crate::units::{Angle, AngleRange, Microseconds, Millis, Percent};

use super::config::{BehaviourConfig, LiveConfig};
use super::fixed::{MAX_SPAN, ONE, Span};

/// The offsets `limits` leave around `pose`.
pub(super) const fn room_around(limits: AngleRange, pose: Angle) -> AngleRange {
    AngleRange {
        min: limits.min.saturating_sub(pose),
        max: limits.max.saturating_sub(pose),
    }
}

/// A validated [`BehaviourConfig`] in the integer form the frame path uses.
///
/// Laid out in the order written (`repr(C)`), what the frame path reads
/// first (see [`Mixer`](super::Mixer)'s layout).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(C)]
pub struct BehaviourParams {
    /// A gesture's fade-out under a newer one.
    pub(crate) blend: Span,
    /// Idle duck depth, Q16.
    pub(crate) duck: u32,
    /// The idle's duck on the look's axes while a look holds, Q16.
    pub(crate) look_duck: u32,
    /// Time in gesture mode after the motion, µs.
    pub(crate) settle: u32,
    /// Time of an idle change, µs.
    pub(crate) idle_fade: u32,
    /// The frame period, µs: the step of the frame path's clock, and the
    /// period of the per-frame `rates`.
    pub(super) frame_us: u32,
    /// The driver's neutral pose.
    pub(super) pose: [Angle; 3],
    /// Offsets each axis may take around the neutral pose (limits − pose).
    pub(super) room: [AngleRange; 3],
    /// The driver's configured limits: the idle mode.
    pub(super) idle_limits: [MotionLimits; 3],
    /// The per-frame rates of both modes' limits (`[idle, gesture]` per
    /// axis) at `frame_us`, computed here (and again when the frame rate
    /// changes, [`set_frame_period`](Self::set_frame_period)) so that a
    /// switch between the modes divides nothing (`None`: the driver refuses
    /// those limits).
    pub(super) rates: [[Option<SlewRates>; 2]; 3],
    pub(super) config: BehaviourConfig,
}

/// The limits an axis is driven with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum LimitMode {
    /// Idle motion only: the driver's configured limits.
    Idle,
    /// A gesture or a gaze move plays (or just did): the gesture limits.
    Gesture,
}

impl LimitMode {
    /// Whether two sets of modes are the same (three byte compares).
    pub(crate) const fn same(a: [Self; 3], b: [Self; 3]) -> bool {
        a[0] as u8 == b[0] as u8 && a[1] as u8 == b[1] as u8 && a[2] as u8 == b[2] as u8
    }
}

impl BehaviourParams {
    /// The configuration these parameters were built from.
    #[must_use]
    pub const fn config(&self) -> &BehaviourConfig {
        &self.config
    }

    /// The frame period in µs.
    #[must_use]
    pub const fn frame_us(&self) -> u32 {
        self.frame_us
    }

    /// Plays frames `period` apart from now on (`servo rate`): the step of
    /// the clock and the per-frame rates of both limit modes (the
    /// durations are in µs and stay). The driver takes the same period
    /// ([`FrameDriver::set_frame_period`](crate::driver::FrameDriver::set_frame_period)).
    pub fn set_frame_period(&mut self, period: Microseconds) {
        if period.0 == 0 {
            return;
        }
        self.frame_us = period.0;
        self.rates = mode_rates(&self.idle_limits, &self.config.gesture_limits, period);
    }

    /// The driver's neutral pose, `[pitch, roll, yaw]`: the gaze's centre.
    #[must_use]
    pub const fn neutral_pose(&self) -> [Angle; 3] {
        self.pose
    }

    /// Takes the rest pose, relax and the look's duck of `live`: the
    /// settings a running head takes between two frames. Returns whether
    /// the rest pose had to be clamped to the servos' limits.
    pub fn set_live(&mut self, live: &LiveConfig) -> bool {
        self.config.rest = live.rest;
        self.config.gaze.duck = live.look_duck;
        self.look_duck = q16(live.look_duck);
        rest_offsets(&self.config, &self.pose, &self.room).1
    }

    /// The rest pose's offsets around the neutral pose, m°, clamped to the
    /// room each axis has (worked out when a rest starts, not kept).
    pub(crate) const fn rest_offsets(&self) -> [i32; 3] {
        rest_offsets(&self.config, &self.pose, &self.room).0
    }

    /// Whether the rest pose lies past the servos' limits (the head rests
    /// clamped to them, at [`rest_pose`](Self::rest_pose)).
    #[must_use]
    pub const fn rest_clamped(&self) -> bool {
        rest_offsets(&self.config, &self.pose, &self.room).1
    }

    /// The rest pose, `[pitch, roll, yaw]` axis angles, as the head rests:
    /// within the servos' limits.
    #[must_use]
    pub fn rest_pose(&self) -> [Angle; 3] {
        let offsets = self.rest_offsets();
        core::array::from_fn(|i| Angle::from_millidegrees(offsets[i]).saturating_add(self.pose[i]))
    }

    /// `target`, an angle of `axis`, as an offset from the neutral pose
    /// within the room the axis has there; and whether it had to be
    /// clamped to get there.
    #[must_use]
    pub fn offset_within(&self, axis: Axis, target: Angle) -> (Angle, bool) {
        let room = self.room(axis);
        let offset = target.saturating_sub(self.pose[axis.index()]);
        let inside = offset.clamp_to(room.min, room.max);
        (inside, inside != offset)
    }

    /// The offsets `axis` may take around its neutral pose.
    #[must_use]
    pub const fn room(&self, axis: Axis) -> AngleRange {
        self.room[axis.index()]
    }

    /// Gives `axis` the servo's new angle `limits` (a calibration changed
    /// while the head runs): looks are clamped to them and gestures checked
    /// against them from now on, as the console checked them.
    pub(crate) fn set_angle_limits(&mut self, axis: Axis, limits: AngleRange) {
        let i = axis.index();
        if let (Some(room), Some(&pose)) = (self.room.get_mut(i), self.pose.get(i)) {
            *room = room_around(limits, pose);
        }
    }

    /// The limits of `axis` in `mode`.
    #[must_use]
    pub const fn limits(&self, axis: Axis, mode: LimitMode) -> MotionLimits {
        match mode {
            LimitMode::Idle => self.idle_limits[axis.index()],
            LimitMode::Gesture => self.config.gesture_limits[axis.index()],
        }
    }

    /// The per-frame rates of [`limits`](Self::limits)`(axis, mode)` at
    /// [`frame_us`](Self::frame_us), if the driver takes those limits.
    pub(crate) const fn rates(&self, axis: Axis, mode: LimitMode) -> Option<SlewRates> {
        self.rates[axis.index()][mode as usize]
    }

    /// `duration` in µs on the frame path's clock (at least 1, saturating).
    #[must_use]
    pub const fn micros(duration: Millis) -> u32 {
        let us = duration.0 as u64 * 1000;
        if us == 0 {
            1
        } else if us > u32::MAX as u64 {
            u32::MAX
        } else {
            us as u32
        }
    }

    /// The duration in µs of a move of `distance` m° that takes at least
    /// `ms`, lengthened to whole ms until its minimum-jerk profile fits
    /// `speed` °/s and `accel` °/s² (it peaks at `1.875·D/T` and
    /// `5.774·D/T²`): never faster than the limits allow (but at most
    /// `MAX_SPAN`).
    pub(crate) fn move_us(ms: u64, distance: u32, speed: u32, accel: u32) -> u32 {
        let d = u64::from(distance);
        let (speed, accel) = (u64::from(speed.max(1)), u64::from(accel.max(1)));
        // T ≥ 1.875·D/v and T² ≥ 5.774·D/a (D in m°, T in ms).
        let squared = (57_735 * d).div_ceil(10 * accel);
        let root = squared.isqrt();
        let ms = ms
            .max((1875 * d).div_ceil(1000 * speed))
            .max(if root * root < squared {
                root + 1
            } else {
                root
            });
        u32::try_from(ms.saturating_mul(1000).min(u64::from(MAX_SPAN)))
            .unwrap_or(MAX_SPAN)
            .max(2)
    }

    /// `us` µs, rounded to ms.
    #[must_use]
    pub const fn millis(us: u32) -> Millis {
        Millis(((us as u64 + 500) / 1000) as u32)
    }
}

/// A percentage as a Q16 fraction.
pub(super) const fn q16(p: Percent) -> u32 {
    (p.get() as u32 * ONE) / 100
}

/// `config`'s rest pose as offsets around the neutral `pose`, each clamped
/// to the `room` its axis has there (the servos' limits), and whether it
/// had to be. (Clamped, not refused: settings saved before the rest pose
/// existed keep loading whatever their limits, as a look's target is
/// clamped.)
pub(super) const fn rest_offsets(
    config: &BehaviourConfig,
    pose: &[Angle; 3],
    room: &[AngleRange; 3],
) -> ([i32; 3], bool) {
    let mut offsets = [0; 3];
    let mut clamped = false;
    let mut i = 0;
    while i < 3 {
        let offset = config.rest.pose[i].saturating_sub(pose[i]);
        let inside = offset.clamp_to(room[i].min, room[i].max);
        clamped |= inside.millidegrees() != offset.millidegrees();
        offsets[i] = inside.millidegrees();
        i += 1;
    }
    (offsets, clamped)
}

/// The per-frame rates of both modes' limits, `[idle, gesture]` per axis,
/// at the frame period `period` (`None` where the driver refuses them).
pub(super) const fn mode_rates(
    idle: &[MotionLimits; 3],
    gesture: &[MotionLimits; 3],
    period: Microseconds,
) -> [[Option<SlewRates>; 2]; 3] {
    let mut rates = [[None; 2]; 3];
    let mut i = 0;
    while i < 3 {
        let axis = Axis::ALL[i];
        rates[i] = [
            match slew_rates(axis, idle[i], period) {
                Ok(r) => Some(r),
                Err(_) => None,
            },
            match slew_rates(axis, gesture[i], period) {
                Ok(r) => Some(r),
                Err(_) => None,
            },
        ];
        i += 1;
    }
    rates
}
