//! Every motion error says what was rejected and what is allowed, in the
//! user's units: `Display` with the value, the static `message()` for logs,
//! and the compile-time error of an invalid built-in configuration.

use idle_head_core::motion::{
    AxisConfig, AxisError, DEFAULT_HEAD, DEFAULT_N, HeadConfig, MAX_N, MAX_STEP, MAX_WINDOW, MIN_N,
    MIN_WINDOW, MotionError,
};
use idle_head_core::{Angle, AngleRange, Axis};

/// The error `cfg` gets on `axis` with `n` samples.
fn rejected(axis: Axis, n: usize, cfg: AxisConfig) -> MotionError {
    cfg.validate(axis, n).expect_err("an invalid configuration")
}

/// The default configuration of `axis`.
fn default(axis: Axis) -> AxisConfig {
    *DEFAULT_HEAD.axis(axis)
}

fn mdeg(min: i32, max: i32) -> AngleRange {
    AngleRange {
        min: Angle::from_millidegrees(min),
        max: Angle::from_millidegrees(max),
    }
}

#[test]
fn angles_and_ranges_display_in_degrees() {
    let shown = |mdeg: i32| Angle::from_millidegrees(mdeg).to_string();
    assert_eq!(shown(-23_000), "-23°");
    assert_eq!(shown(4_500), "4.5°");
    assert_eq!(shown(-250), "-0.25°");
    assert_eq!(shown(1), "0.001°");
    assert_eq!(shown(-32_767), "-32.767°");
    assert_eq!(shown(10_050), "10.05°");
    assert_eq!(shown(0), "0°");
    assert_eq!(shown(i32::MIN), "-2147483.648°");
    assert_eq!(AngleRange::degrees(-23, 32).to_string(), "-23°..32°");
    assert_eq!(mdeg(5_000, -5_000).to_string(), "5°..-5°");
}

#[test]
fn length_too_short() {
    let e = rejected(Axis::Pitch, 10, default(Axis::Pitch));
    assert_eq!(e, MotionError::LengthTooShort { n: 10, min: MIN_N });
    assert_eq!(e.message(), "N (samples per loop): must be at least 16");
    assert_eq!(
        e.to_string(),
        "N (samples per loop) = 10: must be at least 16"
    );
}

#[test]
fn length_too_long() {
    let e = rejected(Axis::Pitch, 9000, default(Axis::Pitch));
    assert_eq!(
        e,
        MotionError::LengthTooLong {
            n: 9000,
            max: MAX_N
        }
    );
    assert_eq!(e.message(), "N (samples per loop): must be at most 8192");
    assert_eq!(
        e.to_string(),
        "N (samples per loop) = 9000: must be at most 8192"
    );
}

#[test]
fn window_too_small() {
    let e = rejected(Axis::Pitch, DEFAULT_N, default(Axis::Pitch).with_window(2));
    assert_eq!(
        e,
        MotionError::WindowTooSmall {
            window: 2,
            min: MIN_WINDOW
        }
    );
    assert_eq!(e.message(), "window W: must be at least 3 taps");
    let axis = AxisError {
        axis: Axis::Pitch,
        error: e,
    };
    assert_eq!(
        axis.to_string(),
        "pitch window W = 2: must be at least 3 taps"
    );
}

#[test]
fn window_too_large_names_the_limit_for_this_n() {
    let e = rejected(Axis::Roll, 100, default(Axis::Roll).with_window(59));
    assert_eq!(
        e,
        MotionError::WindowTooLarge {
            window: 59,
            max: 50
        }
    );
    assert_eq!(
        e.message(),
        "window W: must be at most N/2 and at most 511 taps"
    );
    assert_eq!(
        e.to_string(),
        "window W = 59: must be at most N/2 and at most 511 taps, allowed at most 50"
    );
    let e = rejected(Axis::Roll, MAX_N, default(Axis::Roll).with_window(600));
    assert_eq!(
        e,
        MotionError::WindowTooLarge {
            window: 600,
            max: MAX_WINDOW
        }
    );
    assert!(e.to_string().ends_with(", allowed at most 511"), "{e}");
}

#[test]
fn step_not_positive() {
    let mut cfg = default(Axis::Yaw);
    cfg.step = Angle::from_millidegrees(-250);
    let e = rejected(Axis::Yaw, DEFAULT_N, cfg);
    assert_eq!(e, MotionError::StepNotPositive { step: cfg.step });
    assert_eq!(e.message(), "step δ: must be positive");
    assert_eq!(e.to_string(), "step δ = -0.25°: must be positive");
}

#[test]
fn step_too_large() {
    let mut cfg = default(Axis::Yaw);
    cfg.step = Angle::from_millidegrees(90_500);
    let e = rejected(Axis::Yaw, DEFAULT_N, cfg);
    assert_eq!(
        e,
        MotionError::StepTooLarge {
            step: cfg.step,
            max: MAX_STEP
        }
    );
    assert_eq!(e.message(), "step δ: must be at most 90°");
    assert_eq!(e.to_string(), "step δ = 90.5°: must be at most 90°");
}

#[test]
fn range_inverted() {
    let e = rejected(
        Axis::Yaw,
        DEFAULT_N,
        default(Axis::Yaw).with_range(mdeg(5_000, -5_000)),
    );
    assert_eq!(
        e,
        MotionError::RangeInverted {
            range: mdeg(5_000, -5_000)
        }
    );
    assert_eq!(e.message(), "range: min must be below max");
    let axis = AxisError {
        axis: Axis::Yaw,
        error: e,
    };
    assert_eq!(axis.to_string(), "yaw range 5°..-5°: min must be below max");
}

#[test]
fn range_excludes_neutral() {
    let range = mdeg(2_000, 9_500);
    let e = rejected(Axis::Yaw, DEFAULT_N, default(Axis::Yaw).with_range(range));
    assert_eq!(e, MotionError::RangeExcludesNeutral { range });
    assert_eq!(
        e.message(),
        "range: must contain 0° (the neutral pose) strictly inside"
    );
    assert_eq!(
        e.to_string(),
        "range 2°..9.5°: must contain 0° (the neutral pose) strictly inside"
    );
}

#[test]
fn range_outside_limits_names_the_axis_limits() {
    let range = AngleRange::degrees(-50, 50);
    let e = rejected(Axis::Yaw, DEFAULT_N, default(Axis::Yaw).with_range(range));
    let limits = Axis::Yaw.anatomical_limits();
    assert_eq!(
        e,
        MotionError::RangeOutsideLimits {
            axis: Axis::Yaw,
            range,
            limits
        }
    );
    assert_eq!(
        e.message(),
        "range: outside the axis' anatomical limits (Table 1)"
    );
    let axis = AxisError {
        axis: Axis::Yaw,
        error: e,
    };
    assert_eq!(
        axis.to_string(),
        "yaw range -50°..50°: outside the axis' anatomical limits (Table 1), allowed -23°..32°"
    );
}

/// Not reachable through validation while Table 1 lies inside the storage
/// (the limits are checked first), so built directly.
#[test]
fn storage_overflow() {
    let e = MotionError::StorageOverflow {
        range: mdeg(-40_000, 1_000),
    };
    assert_eq!(
        e.message(),
        "range: does not fit the i16 millidegree storage"
    );
    assert_eq!(
        e.to_string(),
        "range -40°..1°: does not fit the i16 millidegree storage, allowed -32.767°..32.767°"
    );
}

#[test]
fn degenerate() {
    let e = MotionError::Degenerate { seed: 8821 };
    assert_eq!(
        e.message(),
        "seed: the smoothed walk is flat, no motion to scale: choose another seed"
    );
    assert_eq!(
        e.to_string(),
        "seed = 8821: the smoothed walk is flat, no motion to scale: choose another seed"
    );
}

/// `assert_valid` panics with what a build of an invalid built-in
/// configuration prints (the `compile_fail` doc tests show that it does
/// fail the build): the axis and the message.
#[test]
#[should_panic(expected = "roll window W: must be at least 3 taps")]
fn compile_time_error_names_axis_and_field() {
    let bad = HeadConfig {
        roll: DEFAULT_HEAD.roll.with_window(2),
        ..DEFAULT_HEAD
    };
    bad.assert_valid(DEFAULT_N);
}

#[test]
#[should_panic(expected = "yaw range: outside the axis' anatomical limits (Table 1)")]
fn compile_time_error_for_a_range() {
    let bad = HeadConfig {
        yaw: DEFAULT_HEAD.yaw.with_range(AngleRange::degrees(-50, 50)),
        ..DEFAULT_HEAD
    };
    bad.assert_valid(DEFAULT_N);
}
