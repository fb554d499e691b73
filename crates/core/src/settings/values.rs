//! The head's settings: one versioned, validated structure.
//!
//! [`Settings`] holds what a person may change at run time and keep in
//! flash: the calibration and limits of the three servos, the behaviour
//! (idle amplitude, gesture and gaze parameters, the rest pose), the idle
//! motion's seeds, the trigger inputs' roles and the DMX receiver's
//! settings. [`Settings::DEFAULT`] is the built-in configuration.
//! [`Settings::validate`] checks them exactly as the typed
//! configurations are checked ([`DriverConfig::build`],
//! [`BehaviourConfig::build`]), against a board's base driver
//! configuration (its frame period, PWM and speed limits).

use crate::text::{Describe, Text, display_from_describe};

use crate::axis::Axis;
use crate::behaviour::{BehaviourConfig, BehaviourError, BehaviourParams};
use crate::command::InputRole;
use crate::dmx::DmxSettings;
use crate::driver::{ConfigError, DriverConfig, DriverParams};
use crate::input::InputSettings;
use crate::motion::DEFAULT_HEAD;
use crate::seed::Seeding;
use crate::servo::{ServoCalibration, ServoRate};
use crate::track::TrackSettings;

/// Everything a person may change and save; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Settings {
    /// Calibration and angle limits per servo, `[pitch, roll, yaw]`.
    pub servos: [ServoCalibration; 3],
    /// Gesture, gaze and idle parameters.
    pub behaviour: BehaviourConfig,
    /// Seeds r(0) of the idle motion's random streams, `[pitch, roll, yaw]`.
    pub seeds: [u32; 3],
    /// The DMX receiver: on or off, and the head's start address.
    pub dmx: DmxSettings,
    /// The trigger inputs' roles and the rest timer.
    pub inputs: InputSettings,
    /// Where the idle's seeds come from ([`crate::seed`]): `seeds` is used
    /// only when chosen.
    pub seeding: Seeding,
    /// The radar and the tracking ([`crate::track`]).
    pub track: TrackSettings,
    /// The servos' PWM rate, and so the frame rate.
    pub rate: ServoRate,
}

/// Why settings are not valid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SettingsError {
    /// A servo calibration the driver rejects.
    Driver(ConfigError),
    /// Behaviour parameters that do not hold with these servos.
    Behaviour(BehaviourError),
}

impl Describe for SettingsError {
    fn describe(&self, out: &mut dyn Text) {
        match self {
            Self::Driver(e) => e.describe(out),
            Self::Behaviour(e) => e.describe(out),
        }
    }
}

display_from_describe!(SettingsError);

impl core::error::Error for SettingsError {}

/// Settings checked against a board's driver configuration: the
/// parameters the frame path uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Validated {
    /// The driver's parameters with these servos.
    pub driver: DriverParams,
    /// The behaviour's parameters for that driver.
    pub behaviour: BehaviourParams,
}

impl Validated {
    /// The built-in settings checked with the built-in driver
    /// configuration, at compile time.
    pub const DEFAULT: Self = match Settings::DEFAULT.validate(&DriverConfig::DEFAULT) {
        Ok(v) => v,
        Err(_) => panic!("the built-in settings fail validation"),
    };
}

impl Settings {
    /// The built-in configuration: the hobby servos of
    /// [`DriverConfig::DEFAULT`], [`BehaviourConfig::DEFAULT`] and the
    /// seeds of the paper's Table 2 ([`DEFAULT_HEAD`]).
    pub const DEFAULT: Self = Self {
        servos: DriverConfig::DEFAULT.servos,
        behaviour: BehaviourConfig::DEFAULT,
        seeds: [
            DEFAULT_HEAD.pitch.seed,
            DEFAULT_HEAD.roll.seed,
            DEFAULT_HEAD.yaw.seed,
        ],
        dmx: DmxSettings::DEFAULT,
        inputs: InputSettings::DEFAULT,
        seeding: Seeding::Board,
        track: TrackSettings::DEFAULT,
        rate: ServoRate::DEFAULT,
    };

    /// `base` with these settings' servos, and their rate's period for the
    /// frames and the PWM.
    #[must_use]
    pub const fn driver_config(&self, base: &DriverConfig) -> DriverConfig {
        let mut config = *base;
        config.servos = self.servos;
        config.frame_period = self.rate.period();
        config.pwm.period = self.rate.period();
        config
    }

    /// Checks the settings at their rate with `base`'s neutral pose and
    /// speed limits, as the typed configurations are checked.
    ///
    /// # Errors
    /// The first problem found: [`SettingsError::Driver`] for a servo,
    /// [`SettingsError::Behaviour`] for the behaviour parameters (which
    /// also must fit the servos' limits).
    pub const fn validate(&self, base: &DriverConfig) -> Result<Validated, SettingsError> {
        let driver = match self.driver_config(base).build() {
            Ok(driver) => driver,
            Err(e) => return Err(SettingsError::Driver(e)),
        };
        match self.behaviour.build(&driver) {
            Ok(behaviour) => Ok(Validated { driver, behaviour }),
            Err(e) => Err(SettingsError::Behaviour(e)),
        }
    }

    /// [`validate`](Self::validate) of settings that differ from valid
    /// ones only in their [`rate`](Self::rate) (`servo rate`): the driver
    /// checked in full at the new rate, the behaviour as
    /// [`BehaviourConfig::build_at_rate`](crate::behaviour::BehaviourConfig::build_at_rate)
    /// checks it (the gestures' defaults, which no frame period changes,
    /// are not planned again). The same result as `validate` for such
    /// settings, at a tenth of its work.
    ///
    /// # Errors
    /// As [`validate`](Self::validate).
    pub const fn validate_rate(&self, base: &DriverConfig) -> Result<Validated, SettingsError> {
        let driver = match self.driver_config(base).build() {
            Ok(driver) => driver,
            Err(e) => return Err(SettingsError::Driver(e)),
        };
        match self.behaviour.build_at_rate(&driver) {
            Ok(behaviour) => Ok(Validated { driver, behaviour }),
            Err(e) => Err(SettingsError::Behaviour(e)),
        }
    }

    /// Checks each button's action with `behaviour` as the console checks
    /// a motion command, on the board's first `used` slots (its inputs):
    /// the first that the head would refuse, with its input's slot. (Not part of [`validate`](Self::validate): a record
    /// loads whatever its buttons say, and a press the head refuses is
    /// logged, not played.)
    ///
    /// # Errors
    /// The input's slot (see [`InputIds`](crate::input::InputIds)) and why.
    pub fn check_inputs(
        &self,
        behaviour: &BehaviourParams,
        used: usize,
    ) -> Result<(), (usize, BehaviourError)> {
        for (n, role) in self.inputs.roles.iter().enumerate().take(used) {
            if let InputRole::Button(action) = role {
                behaviour.check(action).map_err(|e| (n, e))?;
            }
        }
        Ok(())
    }

    /// The calibration of `axis`' servo.
    #[must_use]
    pub const fn servo(&self, axis: Axis) -> &ServoCalibration {
        &self.servos[axis.index()]
    }

    /// The three seeds that `seed <n>` gives: `n` for pitch, then two
    /// more drawn from it (the same `n`, the same motion).
    #[must_use]
    pub const fn seeds_from(n: u32) -> [u32; 3] {
        // Two steps of a 32-bit LCG (Numerical Recipes' constants), so
        // that the axes' streams differ.
        let roll = n.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let yaw = roll.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        [n, roll, yaw]
    }
}

/// Where the settings in effect came from (`status`'s `settings=`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SettingsSource {
    /// The built-in settings.
    Defaults,
    /// Loaded from (or just saved to) flash.
    Flash,
    /// Changed since, not saved.
    Changed,
}

impl SettingsSource {
    /// The word in `status`.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Defaults => "defaults",
            Self::Flash => "flash",
            Self::Changed => "changed",
        }
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

// The built-in settings are valid with the built-in driver.
const _: () = assert!(Settings::DEFAULT.validate(&DriverConfig::DEFAULT).is_ok());
