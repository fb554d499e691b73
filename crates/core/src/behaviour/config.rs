//! The behaviour's settings in physical units ([`BehaviourConfig`]) and
//! their validated integer form ([`BehaviourParams`]).
//!
//! Like the driver's configuration, a built-in value is checked at compile
//! time ([`BehaviourConfig::assert_valid`]) and a run-time one gets a typed
//! [`BehaviourError`] naming the field, the value and the allowed range.
//!
//! # Limit modes
//!
//! The driver's speed and acceleration limits guard against a broken
//! trajectory; the idle motion moves at most about 8 °/s and 20 °/s², so the
//! driver's configured limits (default 60 °/s, 600 °/s²) are the *idle* mode.
//! A brisk nod needs more: the *gesture* mode ([`BehaviourConfig::gesture_limits`],
//! default 250 °/s and 5000 °/s² on every axis, half a hobby servo's
//! ~500 °/s) holds on an axis while a gesture or a gaze move plays on it and
//! for [`BehaviourConfig::settle`] (500 ms) after, so that the axis is at
//! rest again before the tighter idle limits return. Every gesture is checked
//! against its axis' gesture limits before it plays ([`BehaviourError::TooFast`],
//! [`BehaviourError::TooBrisk`]), so the limiter never flattens a valid one.

use const_format::concatcp;

use crate::axis::Axis;
use crate::command::{GestureKind, GestureRequest, Hold, Percent};
use crate::driver::{
    DegreesPerSecond, DegreesPerSecondSquared, DriverParams, MotionLimits, SlewRates, slew_rates,
};
use crate::units::{Angle, AngleRange, Millis};

use super::error::BehaviourError;
use super::fixed::{MAX_FRAMES, ONE, inverse};
use super::gesture;

/// `value` % (a compile-time constant below 100).
const fn percent(value: u8) -> Percent {
    match Percent::new(value) {
        Some(p) => p,
        None => panic!("a percentage is at most 100"),
    }
}

const fn min(a: i64, b: i64) -> i64 {
    if a < b { a } else { b }
}

const KINDS: [GestureKind; 3] = [GestureKind::Nod, GestureKind::Shake, GestureKind::Tilt];

/// Returns a [`BehaviourError::Config`] from the enclosing `const fn` unless
/// `min ≤ value ≤ max`.
macro_rules! check {
    ($field:expr, $unit:literal, $value:expr, $min:expr, $max:expr) => {{
        let (value, min, max) = ($value as i64, $min as i64, $max as i64);
        if value < min || value > max {
            return Err(BehaviourError::Config {
                field: $field,
                unit: $unit,
                value,
                min,
                max,
            });
        }
    }};
}

/// The gesture mode's limits of one axis: at least the idle mode's, at most
/// far beyond any hobby servo.
macro_rules! check_limits {
    ($field:literal, $gesture:expr, $idle:expr) => {{
        check!(
            concatcp!($field, ".max_speed"),
            "°/s",
            $gesture.max_speed.0,
            $idle.max_speed.0,
            2000
        );
        check!(
            concatcp!($field, ".max_accel"),
            "°/s²",
            $gesture.max_accel.0,
            $idle.max_accel.0,
            100_000
        );
    }};
}

/// A gesture's default cycles and frequencies.
macro_rules! check_defaults {
    ($kind:literal, $d:expr, $cap:expr) => {{
        check!(
            concatcp!($kind, ".cycles"),
            "cycles",
            $d.cycles,
            1,
            MAX_CYCLES
        );
        check!(concatcp!($kind, ".slow"), "mHz", $d.slow.0, 100, $d.brisk.0);
        check!(
            concatcp!($kind, ".brisk"),
            "mHz",
            $d.brisk.0,
            $d.slow.0,
            $cap.0
        );
    }};
}

/// A frequency in millihertz (1 LSB = 0.001 Hz).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MilliHertz(pub u32);

/// The defaults of one gesture; see [`gesture`](super::gesture) for what
/// they shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GestureDefaults {
    /// Peak amplitude of the first cycle at 50 % intensity.
    pub amplitude: Angle,
    /// Cycles when not asked for (a tilt always has one).
    pub cycles: u8,
    /// Cycle frequency at 0 % intensity.
    pub slow: MilliHertz,
    /// Cycle frequency at 100 % intensity.
    pub brisk: MilliHertz,
    /// Intensity when not asked for.
    pub intensity: Percent,
}

/// Gaze moves: how long they take and how long the head stays.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GazeConfig {
    /// Duration of a move, fixed part.
    pub base: Millis,
    /// Duration of a move, per degree of the larger of its two axis moves.
    pub per_degree: Millis,
    /// What a look does once there, when not asked for.
    pub hold: Hold,
    /// Longest move (a given duration may not exceed it).
    pub longest: Millis,
}

/// The idle layer under gestures and gaze.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct IdleConfig {
    /// Idle amplitude at start (`idle amp`).
    pub amplitude: Percent,
    /// How much of the idle motion a gesture's axis loses while the gesture
    /// plays at full strength.
    pub duck: Percent,
    /// Time of an idle change (`idle on|off`, `idle amp`).
    pub fade: Millis,
}

/// Everything the behaviour layer needs, in physical units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BehaviourConfig {
    /// Nod defaults (pitch).
    pub nod: GestureDefaults,
    /// Shake defaults (yaw).
    pub shake: GestureDefaults,
    /// Tilt defaults (roll).
    pub tilt: GestureDefaults,
    /// Highest cycle frequency of any gesture.
    pub max_frequency: MilliHertz,
    /// Longest gesture.
    pub longest_gesture: Millis,
    /// Time an interrupted gesture takes to fade out under the new one.
    pub blend: Millis,
    /// Gaze moves.
    pub gaze: GazeConfig,
    /// The idle layer.
    pub idle: IdleConfig,
    /// Speed and acceleration limits of the gesture mode, `[pitch, roll, yaw]`
    /// (the idle mode's are the driver's configured ones).
    pub gesture_limits: [MotionLimits; 3],
    /// How long an axis stays in gesture mode after its motion ended.
    pub settle: Millis,
}

/// Most cycles of one gesture.
pub const MAX_CYCLES: u8 = 32;
/// Longest hold of a look before it returns (`hold=stay` has none).
pub const MAX_HOLD: Millis = Millis(3_600_000);

/// The gesture mode's default limits on every axis.
const GESTURE_LIMITS: MotionLimits = MotionLimits {
    max_speed: DegreesPerSecond(250),
    max_accel: DegreesPerSecondSquared(5000),
};

impl BehaviourConfig {
    /// The defaults (see the [gesture module](super::gesture) for the shapes):
    ///
    /// | | amplitude (50 %) | cycles | 0 % … 100 % intensity |
    /// |---|---|---|---|
    /// | nod | 6° | 2 | 1.5 … 3.5 Hz |
    /// | shake | 8° | 3 | 1.2 … 2.5 Hz |
    /// | tilt | 10° | 1 | 2.5 s … 1 s (0.4 … 1 Hz) |
    ///
    /// Intensity 50 %; frequency cap 4 Hz; gestures up to 10 s; an
    /// interrupted gesture fades out in 250 ms. Gaze: 300 ms + 8 ms per
    /// degree, back to centre after 3 s, moves up to 8 s. Idle at 100 %,
    /// ducked by 60 % under a gesture, changes over 1 s. Gesture mode
    /// 250 °/s and 5000 °/s², for 500 ms after the motion.
    pub const DEFAULT: Self = Self {
        nod: GestureDefaults {
            amplitude: Angle::from_degrees(6),
            cycles: 2,
            slow: MilliHertz(1500),
            brisk: MilliHertz(3500),
            intensity: Percent::HALF,
        },
        shake: GestureDefaults {
            amplitude: Angle::from_degrees(8),
            cycles: 3,
            slow: MilliHertz(1200),
            brisk: MilliHertz(2500),
            intensity: Percent::HALF,
        },
        tilt: GestureDefaults {
            amplitude: Angle::from_degrees(10),
            cycles: 1,
            slow: MilliHertz(400),
            brisk: MilliHertz(1000),
            intensity: Percent::HALF,
        },
        max_frequency: MilliHertz(4000),
        longest_gesture: Millis(10_000),
        blend: Millis(250),
        gaze: GazeConfig {
            base: Millis(300),
            per_degree: Millis(8),
            hold: Hold::Return(Millis(3000)),
            longest: Millis(8000),
        },
        idle: IdleConfig {
            amplitude: Percent::FULL,
            duck: percent(60),
            fade: Millis(1000),
        },
        gesture_limits: [GESTURE_LIMITS; 3],
        settle: Millis(500),
    };

    /// The defaults of gesture `kind`.
    #[must_use]
    pub const fn defaults(&self, kind: GestureKind) -> &GestureDefaults {
        match kind {
            GestureKind::Nod => &self.nod,
            GestureKind::Shake => &self.shake,
            GestureKind::Tilt => &self.tilt,
        }
    }

    /// Fails compilation (in a `const` context) with a message naming the
    /// field if the configuration is invalid for `driver`.
    ///
    /// ```
    /// use idle_head_core::behaviour::BehaviourConfig;
    /// use idle_head_core::driver::{DriverConfig, DriverParams};
    /// const DRIVER: DriverParams = match DriverConfig::DEFAULT.build() {
    ///     Ok(p) => p,
    ///     Err(e) => panic!("{}", e.message()),
    /// };
    /// const _: () = BehaviourConfig::DEFAULT.assert_valid(&DRIVER);
    /// ```
    ///
    /// # Panics
    /// If [`build`](Self::build) fails (at compile time when used in a `const`).
    pub const fn assert_valid(&self, driver: &DriverParams) {
        if let Err(e) = self.build(driver) {
            e.panic();
        }
    }

    /// Validates the configuration for the head `driver` drives (its frame
    /// period, limits, neutral pose and idle limits) into the integer
    /// parameters of the frame path.
    ///
    /// # Errors
    /// The first problem found, as a [`BehaviourError`].
    ///
    /// ```
    /// use idle_head_core::behaviour::{BehaviourConfig, BehaviourError};
    /// use idle_head_core::driver::DriverConfig;
    /// use idle_head_core::Millis;
    /// let driver = DriverConfig::DEFAULT.build().unwrap();
    /// let mut cfg = BehaviourConfig::DEFAULT;
    /// cfg.gaze.per_degree = Millis(900);
    /// let err = cfg.build(&driver).unwrap_err();
    /// assert_eq!(
    ///     err.to_string(),
    ///     "behaviour config `gaze.per_degree` = 900 ms: must be in 0..=100 ms"
    /// );
    /// ```
    pub const fn build(&self, driver: &DriverParams) -> Result<BehaviourParams, BehaviourError> {
        let cfg = driver.config();
        let frame_us = cfg.frame_period.0;
        // Frame rate in mHz: at least 8 frames per cycle at the cap.
        let top_mhz = (1_000_000_000 / frame_us as u64 / 8) as i64;
        // Every timed move fits the frame path's reciprocals.
        let most_ms = MAX_FRAMES as i64 * frame_us as i64 / 1000;
        check!("max_frequency", "mHz", self.max_frequency.0, 500, top_mhz);
        check!(
            "longest_gesture",
            "ms",
            self.longest_gesture.0,
            100,
            min(60_000, most_ms)
        );
        check!("blend", "ms", self.blend.0, 20, 2000);
        check!("gaze.base", "ms", self.gaze.base.0, 0, 5000);
        check!("gaze.per_degree", "ms", self.gaze.per_degree.0, 0, 100);
        check!(
            "gaze.longest",
            "ms",
            self.gaze.longest.0,
            100,
            min(10_000, most_ms)
        );
        if let Hold::Return(hold) = self.gaze.hold {
            check!("gaze.hold", "ms", hold.0, 0, MAX_HOLD.0 as i64);
        }
        check!(
            "idle.fade",
            "ms",
            self.idle.fade.0,
            20,
            min(10_000, most_ms)
        );
        check!("settle", "ms", self.settle.0, 0, 5000);

        let mut room = [AngleRange {
            min: Angle::ZERO,
            max: Angle::ZERO,
        }; 3];
        let mut i = 0;
        while i < 3 {
            room[i] = room_around(cfg.servos[i].limits, cfg.neutral_pose[i]);
            let idle = cfg.motion[i];
            let gesture = self.gesture_limits[i];
            match Axis::ALL[i] {
                Axis::Pitch => {
                    check_limits!("gesture_limits[pitch]", gesture, idle);
                }
                Axis::Roll => {
                    check_limits!("gesture_limits[roll]", gesture, idle);
                }
                Axis::Yaw => {
                    check_limits!("gesture_limits[yaw]", gesture, idle);
                }
            }
            i += 1;
        }

        let mut params = BehaviourParams {
            config: *self,
            frame_us,
            room,
            idle_limits: cfg.motion,
            rates: [[None; 2]; 3],
            blend: 0,
            blend_inverse: 0,
            settle: 0,
            idle_fade: 0,
            duck: (self.idle.duck.get() as u32 * ONE) / 100,
            pose: cfg.neutral_pose,
        };
        params.rates = mode_rates(cfg, &self.gesture_limits);
        params.blend = params.frames(self.blend);
        params.blend_inverse = inverse(params.blend);
        params.settle = params.frames(self.settle);
        params.idle_fade = params.frames(self.idle.fade);

        // Each gesture's defaults, at both ends of the intensity range.
        let mut k = 0;
        while k < 3 {
            let kind = KINDS[k];
            let d = self.defaults(kind);
            match kind {
                GestureKind::Nod => check_defaults!("nod", d, self.max_frequency),
                GestureKind::Shake => check_defaults!("shake", d, self.max_frequency),
                GestureKind::Tilt => check_defaults!("tilt", d, self.max_frequency),
            }
            let mut request = GestureRequest::new(kind);
            request.intensity = Some(Percent::FULL);
            if let Err(e) = gesture::plan(&params, &request) {
                return Err(e);
            }
            request.intensity = Some(Percent::ZERO);
            if let Err(e) = gesture::plan(&params, &request) {
                return Err(e);
            }
            k += 1;
        }
        Ok(params)
    }
}

// The built-in configuration must be valid with the built-in driver: a
// mistake fails the build.
const _: () = match crate::driver::DriverConfig::DEFAULT.build() {
    Ok(driver) => BehaviourConfig::DEFAULT.assert_valid(&driver),
    Err(e) => panic!("{}", e.message()),
};

/// The offsets `limits` leave around `pose`.
const fn room_around(limits: AngleRange, pose: Angle) -> AngleRange {
    AngleRange {
        min: limits.min.saturating_sub(pose),
        max: limits.max.saturating_sub(pose),
    }
}

/// The per-frame rates of both modes' limits, `[idle, gesture]` per axis,
/// at the driver's frame period (`None` where the driver refuses them).
const fn mode_rates(
    cfg: &crate::driver::DriverConfig,
    gesture: &[MotionLimits; 3],
) -> [[Option<SlewRates>; 2]; 3] {
    let mut rates = [[None; 2]; 3];
    let mut i = 0;
    while i < 3 {
        let axis = Axis::ALL[i];
        let period = cfg.frame_period;
        rates[i] = [
            match slew_rates(axis, cfg.motion[i], period) {
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

/// A validated [`BehaviourConfig`] in the integer form the frame path uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BehaviourParams {
    config: BehaviourConfig,
    frame_us: u32,
    /// Offsets each axis may take around the neutral pose (limits − pose).
    room: [AngleRange; 3],
    /// The driver's configured limits: the idle mode.
    idle_limits: [MotionLimits; 3],
    /// The per-frame rates of both modes' limits (`[idle, gesture]` per
    /// axis) at `frame_us`, computed here so that a switch between the modes
    /// divides nothing (`None`: the driver refuses those limits).
    rates: [[Option<SlewRates>; 2]; 3],
    /// Frames of a gesture's fade-out under a newer one, and its reciprocal.
    pub(crate) blend: u32,
    pub(crate) blend_inverse: u32,
    /// Frames in gesture mode after the motion.
    pub(crate) settle: u32,
    /// Frames of an idle change.
    pub(crate) idle_fade: u32,
    /// The driver's neutral pose.
    pose: [Angle; 3],
    /// Idle duck depth, Q16.
    pub(crate) duck: u32,
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

    /// The driver's neutral pose, `[pitch, roll, yaw]`: the gaze's centre.
    #[must_use]
    pub const fn neutral_pose(&self) -> [Angle; 3] {
        self.pose
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

    /// Checks `action` as [`Mixer::apply`](super::Mixer::apply) would on a
    /// head at rest: every check but the ones that depend on what plays
    /// ([`BehaviourError::Busy`]). For replies before an action is queued:
    /// what the mixer would start, such as where a look goes and whether
    /// its target was clamped.
    ///
    /// # Errors
    /// The [`BehaviourError`] the mixer would answer.
    pub fn check(&self, action: &crate::command::Action) -> Result<super::Applied, BehaviourError> {
        super::Mixer::new(*self).apply(action)
    }

    /// Whole frames in `duration` (rounded, at least 1).
    #[must_use]
    pub const fn frames(&self, duration: Millis) -> u32 {
        let frame_us = if self.frame_us == 0 {
            1
        } else {
            self.frame_us as u64
        };
        let frames = (duration.0 as u64 * 1000 + frame_us / 2) / frame_us;
        if frames == 0 {
            1
        } else if frames > u32::MAX as u64 {
            u32::MAX
        } else {
            frames as u32
        }
    }

    /// The duration of `frames` frames, rounded to ms.
    #[must_use]
    pub const fn millis(&self, frames: u32) -> Millis {
        Millis(((frames as u64 * self.frame_us as u64 + 500) / 1000) as u32)
    }
}
