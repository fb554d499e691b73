//! [`BehaviourConfig::build`]: a configuration in physical units checked
//! into the integer [`BehaviourParams`] of the frame path.
//!
//! Like the driver's configuration, a built-in value is checked at compile
//! time ([`BehaviourConfig::assert_valid`]) and a run-time one gets a typed
//! [`BehaviourError`] naming the field, the value and the allowed range.
//! Each gesture's defaults are checked by planning the gesture at both ends
//! of the intensity range, as a request would be.

use const_format::concatcp;

use crate::axis::Axis;
use crate::command::{GestureRequest, Hold};
use crate::driver::DriverParams;
use crate::gestures::{GestureKind, MAX_CYCLES};
use crate::units::{Angle, AngleRange, Percent};

use super::config::{BehaviourConfig, MAX_HOLD};
use super::error::BehaviourError;
use super::fixed::{MAX_SPAN, Span};
use super::gesture;
use super::params::{BehaviourParams, mode_rates, q16, room_around};

const fn min(a: i64, b: i64) -> i64 {
    if a < b { a } else { b }
}

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

/// A gesture's default cycles and frequencies (`$f`: its row's field names).
macro_rules! check_defaults {
    ($f:expr, $d:expr, $max_cycles:expr, $cap:expr) => {{
        check!($f.cycles, "cycles", $d.cycles, 1, $max_cycles);
        check!($f.slow, "mHz", $d.slow.0, 100, $d.brisk.0);
        check!($f.brisk, "mHz", $d.brisk.0, $d.slow.0, $cap.0);
    }};
}

impl BehaviourConfig {
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
        match self.build_at_rate(driver) {
            Ok(params) => match self.check_gestures(&params) {
                Ok(()) => Ok(params),
                Err(e) => Err(e),
            },
            Err(e) => Err(e),
        }
    }

    /// [`build`](Self::build) without planning each gesture's defaults:
    /// for a configuration that `build` accepted with a driver that
    /// differs from `driver` only in its frame period (`servo rate`). The
    /// plans read the configuration, the servos' room and the limits in
    /// °/s and °/s², never the frame period, so they hold at every rate;
    /// the frame period enters only the frequency cap and the per-frame
    /// rates, checked and worked out here. (The gesture plans are most of
    /// `build`'s work: 64-bit divisions, a port task's CPU on a Cortex-M0+.)
    ///
    /// # Errors
    /// The first problem found, as a [`BehaviourError`].
    pub const fn build_at_rate(
        &self,
        driver: &DriverParams,
    ) -> Result<BehaviourParams, BehaviourError> {
        let cfg = driver.config();
        let frame_us = cfg.frame_period.0;
        // Frame rate in mHz: at least 8 frames per cycle at the cap.
        let top_mhz = (1_000_000_000 / frame_us as u64 / 8) as i64;
        // Every timed move fits the frame path's clock.
        let most_ms = MAX_SPAN as i64 / 1000;
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

        let params = BehaviourParams {
            config: *self,
            frame_us,
            room,
            idle_limits: cfg.motion,
            rates: mode_rates(&cfg.motion, &self.gesture_limits, cfg.frame_period),
            blend: Span::new(BehaviourParams::micros(self.blend)),
            settle: BehaviourParams::micros(self.settle),
            idle_fade: BehaviourParams::micros(self.idle.fade),
            duck: q16(self.idle.duck),
            look_duck: q16(self.gaze.duck),
            pose: cfg.neutral_pose,
        };
        Ok(params)
    }

    /// Each gesture's defaults, at both ends of the intensity range,
    /// planned with `params`.
    const fn check_gestures(&self, params: &BehaviourParams) -> Result<(), BehaviourError> {
        let mut k = 0;
        while k < GestureKind::COUNT {
            let row = GestureKind::ALL[k].row();
            let d = self.defaults(row.kind);
            // The default count may be anything a gesture could have
            // (1..=MAX_CYCLES), as settings saved by earlier firmware hold:
            // a request without cycles plays at most the gesture's own
            // `max_cycles` (a posture: its one), see `gesture::plan`.
            check_defaults!(row.fields, d, MAX_CYCLES, self.max_frequency);
            let mut request = GestureRequest::new(row.kind);
            request.intensity = Some(Percent::FULL);
            if let Err(e) = gesture::plan(params, &request) {
                return Err(e);
            }
            request.intensity = Some(Percent::ZERO);
            if let Err(e) = gesture::plan(params, &request) {
                return Err(e);
            }
            k += 1;
        }
        Ok(())
    }
}

// The built-in configuration must be valid with the built-in driver: a
// mistake fails the build.
const _: () = match crate::driver::DriverConfig::DEFAULT.build() {
    Ok(driver) => BehaviourConfig::DEFAULT.assert_valid(&driver),
    Err(e) => panic!("{}", e.message()),
};
