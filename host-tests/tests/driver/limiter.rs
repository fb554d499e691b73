//! The speed and acceleration limiter: steps, reversals, smooth motion left
//! alone, the approach to the neutral pose, braking for the angle limits.

use host_tests::{mdeg, params};
use idle_head_core::driver::{DriverConfig, FrameDriver};
use idle_head_core::{Angle, Axis, Millis};

use super::{angles, duties, pitch_angles, recorders};

#[test]
fn a_step_is_limited_in_speed_and_acceleration() {
    let mut cfg = DriverConfig::DEFAULT;
    cfg.fade = Millis(0);
    let p = params(&cfg);
    // 60 °/s at 20 ms: 1.2° per frame. 600 °/s²: 0.24° per frame².
    assert_eq!(p.max_step(Axis::Pitch), Angle::from_millidegrees(1200));
    let mut d = FrameDriver::new(recorders(), p);
    d.start();
    let a = pitch_angles(&mut d, [20_000, 0, 0], 60);
    assert_eq!(a[..6], [240, 720, 1440, 2400, 3600, 4800]);
    let steps: Vec<i32> = a.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(steps.iter().all(|&s| (0..=1200).contains(&s)), "{steps:?}");
    let accel = steps.windows(2).map(|w| (w[1] - w[0]).abs()).max().unwrap();
    assert!(accel <= 241, "{accel}: {a:?}"); // 240 m° plus 1 m° of rounding
    // Reaches the target without overshoot within 0.43 s (+ braking), then holds.
    let reached = a.iter().position(|&x| x == 20_000).unwrap();
    assert!(reached < 30, "{a:?}");
    assert!(a[reached..].iter().all(|&x| x == 20_000));
}

#[test]
fn a_step_back_and_forth_settles_without_ringing() {
    let mut cfg = DriverConfig::DEFAULT;
    cfg.fade = Millis(0);
    let mut d = FrameDriver::new(recorders(), params(&cfg));
    d.start();
    pitch_angles(&mut d, [15_000, 0, 0], 10); // still accelerating
    let a = pitch_angles(&mut d, [-10_000, 0, 0], 80);
    let steps: Vec<i32> = a.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(steps.iter().all(|s| s.abs() <= 1200));
    let min = *a.iter().min().unwrap();
    assert_eq!(min, -10_000, "no overshoot");
    assert_eq!(a[40..], [-10_000; 40]);
}

#[test]
fn smooth_motion_within_the_limits_is_untouched() {
    // 10° amplitude, 4 s period, starting at rest: 15.7 °/s and 24.7 °/s² at most.
    let mut cfg = DriverConfig::DEFAULT;
    cfg.fade = Millis(0);
    let mut d = FrameDriver::new(recorders(), params(&cfg));
    d.start();
    for k in 0..400 {
        let phase = core::f64::consts::TAU * f64::from(k) / 200.0;
        let target = (10_000.0 * (1.0 - phase.cos())).round() as i32;
        let r = d.write_frame(mdeg([target, target / 2, -target]));
        assert_eq!(angles(&r), [target, target / 2, -target], "frame {k}");
    }
}

#[test]
fn neutral_pose_is_approached_gently_after_the_neutral_start() {
    let mut cfg = DriverConfig::DEFAULT;
    cfg.neutral_pose = mdeg([5000, -3000, 0]);
    let mut d = FrameDriver::new(recorders(), params(&cfg));
    assert_eq!(duties(&d.start()), [1500; 3]);
    let a = pitch_angles(&mut d, [0; 3], 50);
    assert_eq!(a[0], 240);
    assert_eq!(*a.last().unwrap(), 5000);
    // 5° at 50 °/s... peak speed stays below the limit, no overshoot.
    assert!(a.windows(2).all(|w| w[1] >= w[0] && w[1] - w[0] <= 1200));
    // 5° → 55.55 µs → 1556 µs.
    assert_eq!(d.release()[0].written.last(), Some(&1556));
}

#[test]
fn a_target_running_into_a_limit_is_braked_for() {
    // Pitch (limit +20°) follows a target rising at 1° per frame (50 °/s,
    // within the speed limit) to 30°: the target stops dead at 20°, the
    // head may not. It leaves the target in time and stops on the limit.
    let mut cfg = DriverConfig::DEFAULT;
    cfg.fade = Millis(0);
    let mut d = FrameDriver::new(recorders(), params(&cfg));
    d.start();
    let mut a = vec![0];
    for k in 1..=60 {
        let target = (k * 1000).min(30_000);
        a.push(
            d.write_frame(mdeg([target, 0, 0])).servos[0]
                .angle
                .millidegrees(),
        );
    }
    let steps: Vec<i32> = a.windows(2).map(|w| w[1] - w[0]).collect();
    // 0.24° per frame² at most (give or take a m° of rounding), also at the limit.
    assert!(
        steps.windows(2).all(|w| (w[1] - w[0]).abs() <= 241),
        "{a:?}"
    );
    assert!(a.iter().all(|&x| x <= 20_000), "{a:?}");
    assert_eq!(a[40..], [20_000; 21]);
    // It catches up with the target (frame 12), follows it exactly, and
    // leaves it 2° before the limit to brake from 1° per frame: 0.86°,
    // 0.62°, 0.38°, 0.14°.
    let following: Vec<usize> = (1..a.len()).filter(|&k| a[k] == k as i32 * 1000).collect();
    assert_eq!(following, (12..=18).collect::<Vec<_>>(), "{a:?}");
    assert_eq!(a[18..23], [18_000, 18_860, 19_480, 19_860, 20_000]);
}
