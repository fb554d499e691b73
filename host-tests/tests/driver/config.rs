//! Configuration errors: what `build` rejects, the fields they name, and
//! their messages in the user's units.

use host_tests::params;
use idle_head_core::driver::{
    ConfigError, DegreesPerSecond, DegreesPerSecondSquared, DriverConfig, MotionLimits,
};
use idle_head_core::servo::ServoError;
use idle_head_core::{Angle, AngleRange, Axis, Microseconds, Millis};

#[test]
fn config_errors_name_the_field() {
    let base = DriverConfig::DEFAULT;
    assert_eq!(base.validate(), Ok(()));
    let check = |edit: &dyn Fn(&mut DriverConfig), want: ConfigError, text: &str| {
        let mut c = base;
        edit(&mut c);
        assert_eq!(c.build().err(), Some(want));
        assert_eq!(c.validate(), Err(want));
        assert!(want.message().contains(text), "{}", want.message());
    };
    check(
        &|c| c.frame_period = Microseconds(0),
        ConfigError::ZeroFramePeriod,
        "`frame_period`",
    );
    check(
        &|c| c.pwm.period = Microseconds(0),
        ConfigError::ZeroPwmPeriod,
        "`pwm.period`",
    );
    check(
        &|c| c.faults.disable_after = Millis(0),
        ConfigError::ZeroDisableAfter,
        "`faults.disable_after`",
    );
    check(
        &|c| c.servos[2].max_pulse = Microseconds(900),
        ConfigError::Servo {
            axis: Axis::Yaw,
            error: ServoError::PulseRangeEmpty {
                min: Microseconds(1000),
                max: Microseconds(900),
            },
        },
        "`servos[yaw].min_pulse`",
    );
    check(
        &|c| c.servos[0].limits = AngleRange::degrees(-50, 20),
        ConfigError::Servo {
            axis: Axis::Pitch,
            error: ServoError::LimitUnreachable {
                angle: Angle::from_degrees(-50),
                needed_us: 944,
                min: Microseconds(1000),
                max: Microseconds(2000),
            },
        },
        "`servos[pitch].limits`",
    );
    check(
        &|c| c.pwm.period = Microseconds(1900),
        ConfigError::PulseLongerThanPeriod {
            axis: Axis::Pitch,
            max_pulse: Microseconds(2000),
            period: Microseconds(1900),
        },
        "`servos[pitch].max_pulse`",
    );
    check(
        &|c| {
            c.servos[2].per_degree = idle_head_core::servo::NanosPerDegree(1000);
            c.servos[2].limits = AngleRange::degrees(-23, 400);
        },
        ConfigError::LimitOutOfRange {
            axis: Axis::Yaw,
            limit: Angle::from_degrees(400),
        },
        "`servos[yaw].limits`",
    );
    check(
        &|c| c.neutral_pose[1] = Angle::from_degrees(-20),
        ConfigError::NeutralPoseOutsideLimits {
            axis: Axis::Roll,
            pose: Angle::from_degrees(-20),
            limits: AngleRange::degrees(-14, 19),
        },
        "`neutral_pose[roll]`",
    );
    check(
        &|c| c.motion[1].max_speed = DegreesPerSecond(0),
        ConfigError::ZeroSpeedLimit { axis: Axis::Roll },
        "`motion[roll].max_speed`",
    );
    check(
        &|c| {
            c.frame_period = Microseconds(1000);
            c.motion[2].max_accel = DegreesPerSecondSquared(0);
        },
        ConfigError::AccelBelowResolution {
            axis: Axis::Yaw,
            max_accel: DegreesPerSecondSquared(0),
            frame_period: Microseconds(1000),
        },
        "`motion[yaw].max_accel`",
    );
    // 1 °/s² at 1 ms frames: 10^6 µ°/s² · 10^-6 s² = 1 µ° per frame²: still fine.
    let mut c = base;
    c.frame_period = Microseconds(1000);
    c.motion[0] = MotionLimits {
        max_speed: DegreesPerSecond(1),
        max_accel: DegreesPerSecondSquared(1),
    };
    assert_eq!(c.validate(), Ok(()));
}

/// Each error names the servo and the field, with the rejected value and what
/// is allowed, in µs and degrees.
#[test]
fn config_errors_read_in_the_users_units() {
    let shown = |edit: &dyn Fn(&mut DriverConfig)| {
        let mut c = DriverConfig::DEFAULT;
        edit(&mut c);
        c.build().unwrap_err().to_string()
    };
    assert_eq!(
        shown(&|c| c.frame_period = Microseconds(0)),
        "frame_period must be longer than 0 µs"
    );
    assert_eq!(
        shown(&|c| c.pwm.period = Microseconds(0)),
        "pwm.period must be longer than 0 µs"
    );
    assert_eq!(
        shown(&|c| c.faults.disable_after = Millis(0)),
        "faults.disable_after must be at least 1 ms"
    );
    assert_eq!(
        shown(&|c| c.servos[1].min_pulse = Microseconds(2500)),
        "roll servo: min_pulse 2500 µs must be below max_pulse 2000 µs"
    );
    assert_eq!(
        shown(&|c| c.servos[0].max_pulse = Microseconds(1700)),
        "pitch servo: limit +20° needs 1722 µs, outside the pulse range 1000..1700 µs"
    );
    assert_eq!(
        shown(&|c| c.pwm.period = Microseconds(1900)),
        "pitch servo: max_pulse 2000 µs is longer than the PWM period of 1900 µs"
    );
    assert_eq!(
        shown(&|c| {
            c.servos[2].per_degree = idle_head_core::servo::NanosPerDegree(1000);
            c.servos[2].limits = AngleRange::degrees(-361, 32);
        }),
        "yaw servo: limit -361° lies beyond ±360°, the widest range the driver takes"
    );
    assert_eq!(
        shown(&|c| c.neutral_pose[1] = Angle::from_millidegrees(-20_500)),
        "roll: neutral_pose -20.5° lies outside the servo's limits -14°..+19°"
    );
    assert_eq!(
        shown(&|c| c.motion[1].max_speed = DegreesPerSecond(0)),
        "roll: motion max_speed must be at least 1 °/s"
    );
    assert_eq!(
        shown(&|c| {
            c.frame_period = Microseconds(100);
            c.motion[2].max_accel = DegreesPerSecondSquared(99);
        }),
        "yaw: motion max_accel 99 °/s² is below 100 °/s², the least the driver resolves \
         (1 µ° per frame²) at frames of 100 µs"
    );
    // The fixed message for `const` checks names the field.
    let err = DriverConfig {
        frame_period: Microseconds(0),
        ..DriverConfig::DEFAULT
    }
    .build()
    .unwrap_err();
    assert!(err.message().contains("`frame_period`"));
    // 100 °/s² at 100 µs frames is exactly 1 µ° per frame²: accepted.
    let mut c = DriverConfig::DEFAULT;
    c.frame_period = Microseconds(100);
    c.motion = [MotionLimits {
        max_speed: DegreesPerSecond(60),
        max_accel: DegreesPerSecondSquared(100),
    }; 3];
    assert_eq!(c.validate(), Ok(()));
    let _ = params(&c);
}
