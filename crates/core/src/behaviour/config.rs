//! The behaviour's settings in physical units ([`BehaviourConfig`]).
//!
//! A plain data module: [`BehaviourConfig::build`] (in `validate.rs`)
//! checks a configuration into the integer [`BehaviourParams`] the frame
//! path uses, and a built-in value is checked at compile time
//! ([`BehaviourConfig::assert_valid`]).
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
//!
//! [`BehaviourParams`]: super::BehaviourParams
//! [`BehaviourError::TooFast`]: super::BehaviourError::TooFast
//! [`BehaviourError::TooBrisk`]: super::BehaviourError::TooBrisk

use crate::command::Hold;
use crate::driver::{DegreesPerSecond, DegreesPerSecondSquared, MotionLimits};
use crate::gestures::{GestureDefaults, GestureKind};
use crate::units::{Angle, MilliHertz, Millis, Percent};

/// `value` % (a compile-time constant below 100).
const fn percent(value: u8) -> Percent {
    match Percent::new(value) {
        Some(p) => p,
        None => panic!("a percentage is at most 100"),
    }
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
    /// How much of the idle motion the look's axes (pitch and yaw) lose
    /// while a look holds, so that the head points where it was asked: 0
    /// leaves the idle at full swing around the target, 100 freezes those
    /// axes on it.
    pub duck: Percent,
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

/// Rest: where the head rests, and whether it relaxes there (see
/// [`super::rest`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RestConfig {
    /// The rest pose, `[pitch, roll, yaw]`, axis angles within the servos'
    /// limits.
    pub pose: [Angle; 3],
    /// Stop the pulses once there (the servos go limp: a head that is not
    /// balanced may slump).
    pub relax: bool,
}

/// The behaviour's settings a running head takes between two frames (the
/// rest of the configuration takes effect at the next boot).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LiveConfig {
    /// The rest pose and relax.
    pub rest: RestConfig,
    /// The look's duck ([`GazeConfig::duck`]).
    pub look_duck: Percent,
}

/// Everything the behaviour layer needs, in physical units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BehaviourConfig {
    /// Each gesture's defaults, in the order of [`GestureKind::ALL`]
    /// (see [`defaults`](Self::defaults)).
    pub gestures: [GestureDefaults; GestureKind::COUNT],
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
    /// Rest.
    pub rest: RestConfig,
}

/// Longest hold of a look before it returns (`hold=stay` has none).
pub const MAX_HOLD: Millis = Millis(3_600_000);

/// The gesture mode's default limits on every axis.
const GESTURE_LIMITS: MotionLimits = MotionLimits {
    max_speed: DegreesPerSecond(250),
    max_accel: DegreesPerSecondSquared(5000),
};

impl BehaviourConfig {
    /// The defaults: each gesture's from its row of the
    /// [gesture table](crate::gestures); frequency cap 4 Hz; gestures up
    /// to 10 s; an interrupted gesture fades out in 250 ms. Gaze: 300 ms +
    /// 8 ms per degree, back to centre after 3 s, moves up to 8 s, the idle
    /// ducked by 80 % on the look's axes while a look holds. Idle at
    /// 100 %, ducked by 60 % under a gesture, changes over 1 s. Gesture
    /// mode 250 °/s and 5000 °/s², for 500 ms after the motion. Rest with a
    /// slight droop (pitch 8°, nose down), the pulses on.
    pub const DEFAULT: Self = Self {
        gestures: GestureKind::DEFAULTS,
        max_frequency: MilliHertz(4000),
        longest_gesture: Millis(10_000),
        blend: Millis(250),
        gaze: GazeConfig {
            base: Millis(300),
            per_degree: Millis(8),
            hold: Hold::Return(Millis(3000)),
            longest: Millis(8000),
            duck: percent(80),
        },
        idle: IdleConfig {
            amplitude: Percent::FULL,
            duck: percent(60),
            fade: Millis(1000),
        },
        gesture_limits: [GESTURE_LIMITS; 3],
        settle: Millis(500),
        rest: RestConfig {
            pose: [Angle::from_millidegrees(8000), Angle::ZERO, Angle::ZERO],
            relax: false,
        },
    };

    /// The settings a running head takes between two frames.
    #[must_use]
    pub const fn live(&self) -> LiveConfig {
        LiveConfig {
            rest: self.rest,
            look_duck: self.gaze.duck,
        }
    }

    /// The defaults of gesture `kind`.
    #[must_use]
    pub const fn defaults(&self, kind: GestureKind) -> &GestureDefaults {
        &self.gestures[kind.index()]
    }

    /// The defaults of gesture `kind`, to change them.
    pub const fn defaults_mut(&mut self, kind: GestureKind) -> &mut GestureDefaults {
        &mut self.gestures[kind.index()]
    }
}
