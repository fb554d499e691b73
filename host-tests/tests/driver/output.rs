//! Duties written: neutral first, pose plus offset, the duty scale, the loop
//! seam, a reversed servo, the angle limits.

use host_tests::{direct_config, mdeg, params, pwm, writes};
use idle_head_core::driver::{FrameDriver, Outcome};
use idle_head_core::servo::Direction;
use idle_head_core::{Angle, LoopSource, Microseconds, Millis, Playback};

use super::{angles, done, duties};

#[test]
fn first_pulse_is_neutral_then_pose_plus_offset() {
    let pitch = pwm(20_000, &writes(&[1500, 1600, 1550]));
    let roll = pwm(20_000, &writes(&[1500, 1400, 1500]));
    let yaw = pwm(20_000, &writes(&[1500, 1500, 1856]));
    let mut d = FrameDriver::new([pitch, roll, yaw], params(&direct_config()));

    let r = d.start();
    assert_eq!(duties(&r), [1500; 3]);
    assert_eq!(r.frame, 0);
    assert_eq!(
        (r.written, r.failed, r.disabled, r.should_log),
        (3, 0, 0, false)
    );
    assert!(r.servos.iter().all(|s| s.outcome == Outcome::Written));

    let r = d.write_frame(mdeg([9000, -9000, 0]));
    assert_eq!(duties(&r), [1600, 1400, 1500]);
    assert_eq!(angles(&r), [9000, -9000, 0]);
    assert_eq!(r.servos[0].pulse, Microseconds(1600));
    // 32° on yaw: 1500 + 32 · 11.111 = 1855.55 → 1856 µs.
    let r = d.write_frame(mdeg([4500, 0, 32_000]));
    assert_eq!(duties(&r), [1550, 1500, 1856]);
    assert_eq!(r.frame, 2);
    assert_eq!(d.stats().frames, 3);
    done(d);
}

#[test]
fn write_frame_before_start_starts() {
    let ch = || pwm(20_000, &writes(&[1500, 1600]));
    let mut d = FrameDriver::new([ch(), ch(), ch()], params(&direct_config()));
    assert_eq!(duties(&d.write_frame(mdeg([9000; 3]))), [1500; 3]);
    assert_eq!(duties(&d.write_frame(mdeg([9000; 3]))), [1600; 3]);
    done(d);
}

#[test]
fn rp2040_duty_scale() {
    // 62 500 ticks per 20 ms: 3.125 ticks per µs. 1600 µs → 5000 ticks.
    let ch = || pwm(62_500, &writes(&[4688, 5000]));
    let mut d = FrameDriver::new([ch(), ch(), ch()], params(&direct_config()));
    d.start();
    d.write_frame(mdeg([9000; 3]));
    done(d);
}

/// A four-sample loop played one sample per frame, then two frames per sample.
const LOOP: [Angle; 4] = [
    Angle::from_millidegrees(0),
    Angle::from_millidegrees(9000),
    Angle::from_millidegrees(18_000),
    Angle::from_millidegrees(4500),
];

#[test]
fn loop_seam_and_reversed_servo() {
    // 18° · 11.111 = 199.998 → 200 µs; 4.5° → 49.9995 → 50 µs.
    let pitch = pwm(20_000, &writes(&[1500, 1500, 1600, 1700, 1550, 1500, 1600]));
    let roll = pwm(20_000, &writes(&[1500, 1500, 1600, 1700, 1550, 1500, 1600]));
    let yaw = pwm(20_000, &writes(&[1500, 1500, 1400, 1300, 1450, 1500, 1400]));
    let mut cfg = direct_config();
    cfg.servos[2] = cfg.servos[2].with_direction(Direction::Reversed);
    let mut d = FrameDriver::new([pitch, roll, yaw], params(&cfg));
    // 4 samples in 80 ms at 20 ms per frame: one sample per frame.
    let play = Playback::new(Millis(80), Microseconds(20_000), 4).unwrap();
    d.start();
    for frame in 0..6 {
        // Frames 0..=3 are samples 0..=3; frame 4 is sample 0 again (the seam).
        let r = d.write_frame(play.offsets(frame, [&LOOP; 3]));
        assert_eq!(r.servos[0].angle, LOOP.angle(frame as usize));
    }
    done(d);
}

#[test]
fn interpolated_seam() {
    // 4 samples in 160 ms: two frames per sample. Frame 7 lies halfway between
    // sample 3 (4.5°) and sample 0 (0°); Catmull-Rom with neighbours 18° and 9°:
    // p = ½[2·4.5 + (0 − 18)·½ + (36 − 22.5 + 0 − 9)·¼ + (13.5 − 0 + 9 − 18)·⅛]
    //   = 0.84375° → 844 m° → 1500 + 9.38 µs → 1509 µs (linear: 2.25° → 1525 µs).
    let play = Playback::new(Millis(160), Microseconds(20_000), 4).unwrap();
    let offsets: Vec<i32> = (6..=9)
        .map(|f| play.offsets(f, [&LOOP; 3])[0].millidegrees())
        .collect();
    assert_eq!(offsets, [4500, 844, 0, 3656]);
    let ch = || pwm(20_000, &writes(&[1500, 1550, 1509, 1500]));
    let mut d = FrameDriver::new([ch(), ch(), ch()], params(&direct_config()));
    d.start();
    for f in 6..=8 {
        d.write_frame(play.offsets(f, [&LOOP; 3]));
    }
    done(d);
}

#[test]
fn angles_are_clamped_to_the_axis_limits() {
    // Pitch −12..20°, roll −14..19°, yaw −23..32°.
    // 20° → 1722 µs; −14° → 1500 − 155.55 → 1344 µs; 32° → 1856 µs; −23° → 1244 µs.
    let pitch = pwm(20_000, &writes(&[1500, 1722, 1500 - 133]));
    let roll = pwm(20_000, &writes(&[1500, 1344, 1711]));
    let yaw = pwm(20_000, &writes(&[1500, 1856, 1244]));
    let mut d = FrameDriver::new([pitch, roll, yaw], params(&direct_config()));
    d.start();
    let r = d.write_frame(mdeg([45_000, -45_000, 90_000]));
    assert_eq!(angles(&r), [20_000, -14_000, 32_000]);
    let r = d.write_frame(mdeg([i32::MIN, i32::MAX, i32::MIN]));
    assert_eq!(angles(&r), [-12_000, 19_000, -23_000]);
    done(d);
}

#[test]
fn start_twice_writes_nothing_more() {
    let ch = || pwm(20_000, &writes(&[1500, 1600]));
    let mut d = FrameDriver::new([ch(), ch(), ch()], params(&direct_config()));
    d.start();
    let r = d.write_frame(mdeg([9000; 3]));
    assert_eq!(d.start(), r);
    assert_eq!(d.stats().frames, 2);
    done(d);
}
