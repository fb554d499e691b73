//! Changes at run time: motion limits (a brisk nod, a lower speed while
//! moving) and servo calibrations (without a jump), validated as `build`.

use host_tests::{Recorder, mdeg, params, pwm, writes};
use idle_head_core::driver::{
    ConfigError, DegreesPerSecond, DegreesPerSecondSquared, DriverConfig, FrameDriver, MotionLimits,
};
use idle_head_core::servo::{Direction, ServoCalibration, ServoError};
use idle_head_core::{Angle, AngleRange, Axis, Microseconds, Millis};

use super::{done, recorders};

/// The default configuration without the fade.
fn unfaded() -> DriverConfig {
    let mut cfg = DriverConfig::DEFAULT;
    cfg.fade = Millis(0);
    cfg
}

/// Steps between consecutive values.
fn steps(values: &[i32]) -> Vec<i32> {
    values.windows(2).map(|w| w[1] - w[0]).collect()
}

/// Runs `frames` frames of constant `offsets` and returns the yaw angles (m°).
fn yaw_angles(d: &mut FrameDriver<Recorder>, offsets: [i32; 3], frames: usize) -> Vec<i32> {
    (0..frames)
        .map(|_| d.write_frame(mdeg(offsets)).servos[2].angle.millidegrees())
        .collect()
}

#[test]
fn a_lower_speed_limit_while_moving_slows_down_at_the_acceleration_limit() {
    let mut d = FrameDriver::new(recorders(), params(&unfaded()));
    d.start();
    let mut a = vec![0];
    // 0.24° per frame² up to 1.2° per frame (60 °/s, 600 °/s²).
    a.extend(yaw_angles(&mut d, [0, 0, 30_000], 6));
    assert_eq!(steps(&a)[4..], [1200, 1200]);
    // 10 °/s: 0.2° per frame.
    let slow = MotionLimits {
        max_speed: DegreesPerSecond(10),
        max_accel: DegreesPerSecondSquared(600),
    };
    assert_eq!(d.set_motion_limits(Axis::Yaw, slow), Ok(()));
    assert_eq!(d.params().config().motion[2], slow);
    a.extend(yaw_angles(&mut d, [0, 0, 30_000], 150));
    let s = steps(&a);
    // Down by the acceleration limit, then at the new speed limit.
    assert_eq!(s[6..12], [960, 720, 480, 240, 200, 200]);
    assert!(s.windows(2).all(|w| (w[1] - w[0]).abs() <= 240), "{s:?}");
    // Braking stays exact: on the target, no overshoot.
    assert_eq!(*a.last().unwrap(), 30_000);
    assert!(a.iter().all(|&x| x <= 30_000));
}

#[test]
fn wider_limits_allow_a_brisk_nod() {
    let mut d = FrameDriver::new(recorders(), params(&unfaded()));
    d.start();
    let brisk = MotionLimits {
        max_speed: DegreesPerSecond(180),
        max_accel: DegreesPerSecondSquared(3000),
    };
    assert_eq!(d.set_motion_limits(Axis::Pitch, brisk), Ok(()));
    let pitch = |d: &mut FrameDriver<Recorder>, target: i32, frames: usize| {
        (0..frames)
            .map(|_| {
                d.write_frame(mdeg([target, 0, 0])).servos[0]
                    .angle
                    .millidegrees()
            })
            .collect::<Vec<_>>()
    };
    let mut a = vec![0];
    a.extend(pitch(&mut d, 15_000, 20));
    a.extend(pitch(&mut d, 0, 20));
    let s = steps(&a);
    // 180 °/s: 3.6° per frame; 3000 °/s²: 1.2° per frame².
    assert_eq!(s[..3], [1200, 2400, 3600]);
    assert!(s.iter().all(|x| x.abs() <= 3600));
    assert!(s.windows(2).all(|w| (w[1] - w[0]).abs() <= 1200), "{s:?}");
    assert_eq!(a[20], 15_000, "there within 0.4 s");
    assert_eq!(*a.last().unwrap(), 0, "and back");
    assert!(a.iter().all(|&x| (0..=15_000).contains(&x)), "no overshoot");
}

#[test]
fn motion_limits_are_checked_as_build_checks_them() {
    let mut d = FrameDriver::new(recorders(), params(&unfaded()));
    let zero = MotionLimits {
        max_speed: DegreesPerSecond(0),
        max_accel: DegreesPerSecondSquared(600),
    };
    assert_eq!(
        d.set_motion_limits(Axis::Roll, zero),
        Err(ConfigError::ZeroSpeedLimit { axis: Axis::Roll })
    );
    let mut cfg = unfaded();
    cfg.frame_period = Microseconds(100);
    let mut d = FrameDriver::new(recorders(), params(&cfg));
    let fine = MotionLimits {
        max_speed: DegreesPerSecond(60),
        max_accel: DegreesPerSecondSquared(99),
    };
    let err = d.set_motion_limits(Axis::Yaw, fine).unwrap_err();
    assert_eq!(
        err,
        ConfigError::AccelBelowResolution {
            axis: Axis::Yaw,
            max_accel: DegreesPerSecondSquared(99),
            frame_period: Microseconds(100),
        }
    );
    // Rejected: the limits in use are unchanged.
    assert_eq!(d.params().config().motion, [MotionLimits::DEFAULT; 3]);
}

/// The pulses (µs, one count each) written to pitch while it moves towards
/// 15°, with `change` applied to its calibration after `at` frames.
fn pitch_pulses(
    change: impl Fn(&mut ServoCalibration),
    at: usize,
) -> (Vec<i32>, FrameDriver<Recorder>) {
    let mut d = FrameDriver::new(recorders(), params(&unfaded()));
    d.start();
    for _ in 0..at {
        d.write_frame(mdeg([15_000, 0, 0]));
    }
    let mut cal = d.params().config().servos[0];
    change(&mut cal);
    assert_eq!(d.set_servo(Axis::Pitch, cal), Ok(()));
    assert_eq!(d.params().config().servos[0], cal);
    for _ in 0..100 {
        d.write_frame(mdeg([15_000, 0, 0]));
    }
    let pulses = d.channels_mut()[0]
        .written
        .iter()
        .map(|&p| i32::from(p))
        .collect();
    (pulses, d)
}

/// Pulses step by at most the speed limit (1.2°/frame = 13.3 µs at
/// 11.111 µs/°) and change step by at most the acceleration limit (0.24° =
/// 2.7 µs), give or take the rounding to whole µs.
fn assert_limited(pulses: &[i32]) {
    let s = steps(pulses);
    assert!(s.iter().all(|x| x.abs() <= 14), "{pulses:?}");
    assert!(s.windows(2).all(|w| (w[1] - w[0]).abs() <= 5), "{pulses:?}");
}

#[test]
fn a_new_neutral_while_moving_moves_the_head_without_a_jump() {
    // Moving at full speed after 8 frames; the neutral pulse 100 µs longer.
    let (pulses, mut d) = pitch_pulses(|cal| cal.neutral = Microseconds(1600), 8);
    assert_limited(&pulses);
    // The head ends where the new calibration puts 15°: 1600 + 166.7 µs.
    assert_eq!(*pulses.last().unwrap(), 1767);
    let r = d.write_frame(mdeg([15_000, 0, 0]));
    assert_eq!(r.servos[0].angle, Angle::from_degrees(15));
}

#[test]
fn a_reversed_direction_while_moving_moves_the_head_without_a_jump() {
    let (pulses, _) = pitch_pulses(|cal| cal.direction = Direction::Reversed, 8);
    assert_limited(&pulses);
    assert_eq!(*pulses.last().unwrap(), 1500 - 167);
}

#[test]
fn a_servo_outside_its_new_limits_moves_back_in_without_a_jump() {
    // At 15° after 40 frames; the new upper limit is 10°.
    let (pulses, mut d) = pitch_pulses(|cal| cal.limits = AngleRange::degrees(-12, 10), 40);
    assert_limited(&pulses);
    assert_eq!(pulses[40], 1667, "at 15° when the limits change");
    assert_eq!(*pulses.last().unwrap(), 1611, "then at the new limit, 10°");
    let r = d.write_frame(mdeg([15_000, 0, 0]));
    assert_eq!(r.servos[0].angle, Angle::from_degrees(10));
}

#[test]
fn a_new_neutral_at_rest_moves_the_head_at_the_limits_exactly() {
    // Pitch holds 0° (1500 µs). With the neutral pulse at 1600 µs, 1500 µs
    // is -9°: the limiter takes over there (-9.001°, the middle of the
    // angles that give 1500 µs) and moves to 0° at 0.24° per frame² and up
    // to 1.2° per frame, braking exactly: -8.761°, -8.281°, -7.561°,
    // -6.601°, -5.401°, -4.201°, -3.001°, -1.921°, -1.081°, -0.480°,
    // -0.120°, 0°; at 11.111 µs per degree from 1600 µs:
    let moves = [
        1503, 1508, 1516, 1527, 1540, 1553, 1567, 1579, 1588, 1595, 1599, 1600, 1600,
    ];
    let mut pitch = writes(&[1500, 1500, 1500]);
    pitch.extend(writes(&moves));
    let still = || pwm(20_000, &writes(&[1500; 3 + 13]));
    let mut d = FrameDriver::new([pwm(20_000, &pitch), still(), still()], params(&unfaded()));
    d.start();
    d.write_frame(mdeg([0; 3]));
    d.write_frame(mdeg([0; 3]));
    let mut cal = d.params().config().servos[0];
    cal.neutral = Microseconds(1600);
    assert_eq!(d.set_servo(Axis::Pitch, cal), Ok(()));
    for _ in 0..moves.len() {
        d.write_frame(mdeg([0; 3]));
    }
    done(d);
}

#[test]
fn a_new_calibration_before_the_start_starts_at_its_neutral_pulse() {
    let mut d = FrameDriver::new(recorders(), params(&unfaded()));
    let mut cal = ServoCalibration::hobby(Axis::Roll);
    cal.neutral = Microseconds(1450);
    assert_eq!(d.set_servo(Axis::Roll, cal), Ok(()));
    let r = d.start();
    assert_eq!(r.servos[1].pulse, Microseconds(1450));
    assert_eq!(d.release()[1].written, [1450]);
}

#[test]
fn a_new_calibration_is_checked_as_build_checks_it() {
    let mut d = FrameDriver::new(recorders(), params(&unfaded()));
    let hobby = ServoCalibration::hobby(Axis::Pitch);
    let rejected = |d: &mut FrameDriver<Recorder>, edit: &dyn Fn(&mut ServoCalibration)| {
        let mut cal = hobby;
        edit(&mut cal);
        d.set_servo(Axis::Pitch, cal).unwrap_err()
    };
    assert_eq!(
        rejected(&mut d, &|c| c.max_pulse = Microseconds(1700)),
        ConfigError::Servo {
            axis: Axis::Pitch,
            error: ServoError::LimitUnreachable {
                angle: Angle::from_degrees(20),
                needed_us: 1722,
                min: Microseconds(1000),
                max: Microseconds(1700),
            }
        }
    );
    assert_eq!(
        rejected(&mut d, &|c| c.max_pulse = Microseconds(25_000)),
        ConfigError::Servo {
            axis: Axis::Pitch,
            error: ServoError::PulseOutsideBounds {
                max: true,
                pulse: Microseconds(25_000),
            }
        }
    );
    let mut cfg = unfaded();
    cfg.neutral_pose[0] = Angle::from_degrees(5);
    let mut d = FrameDriver::new(recorders(), params(&cfg));
    assert_eq!(
        rejected(&mut d, &|c| c.limits = AngleRange::degrees(-12, 4)),
        ConfigError::NeutralPoseOutsideLimits {
            axis: Axis::Pitch,
            pose: Angle::from_degrees(5),
            limits: AngleRange::degrees(-12, 4),
        }
    );
    // Rejected: the calibration in use is unchanged.
    assert_eq!(d.params().config().servos[0], hobby);
}
