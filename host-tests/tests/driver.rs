//! The frame driver through the embedded-hal PWM mock: exact duties, faults,
//! limits, fade, and the frame clock.

use embedded_hal::pwm::ErrorKind;
use embedded_hal_mock::eh1::pwm::{Mock, Transaction};
use host_tests::{Recorder, direct_config, failing, mdeg, params, pwm, writes};
use idle_head::driver::{
    ConfigError, DegreesPerSecond, DegreesPerSecondSquared, DriverConfig, FaultPolicy, FrameClock,
    FrameDriver, FrameReport, FrameTick, MotionLimits, Outcome, ZeroPeriod,
};
use idle_head::servo::{Direction, Duty, ServoError};
use idle_head::{Angle, AngleRange, Axis, LoopSource, Microseconds, Millis, Playback};

fn done(driver: FrameDriver<Mock>) {
    for mut ch in driver.release() {
        ch.done();
    }
}

fn duties(r: &FrameReport) -> [u16; 3] {
    r.servos.map(|s| s.duty.0)
}

fn angles(r: &FrameReport) -> [i32; 3] {
    r.servos.map(|s| s.angle.millidegrees())
}

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
fn a_write_error_is_counted_others_keep_moving_and_it_is_retried() {
    let mut cfg = direct_config();
    cfg.faults.disable_after = 3;
    let pitch = pwm(
        20_000,
        &[
            Transaction::set_duty_cycle(1500),
            failing(1600),                     // frame 1: fails
            Transaction::set_duty_cycle(1600), // frame 2: retried, works
            failing(1600),                     // frames 3, 4, 5: fail; the third switches it off
            failing(1600),
            failing(1600),
            Transaction::set_duty_cycle(0), // duty 0: no pulses, the servo goes limp
        ],
    );
    let roll = pwm(
        20_000,
        &writes(&[1500, 1400, 1400, 1400, 1400, 1400, 1400, 1400]),
    );
    let yaw = pwm(
        20_000,
        &writes(&[1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500]),
    );
    let mut d = FrameDriver::new([pitch, roll, yaw], params(&cfg));
    d.start();
    let off = mdeg([9000, -9000, 0]);

    let r = d.write_frame(off);
    assert_eq!(r.servos[0].outcome, Outcome::Failed(ErrorKind::Other));
    assert_eq!(r.servos[0].duty, Duty(1600));
    assert_eq!((r.written, r.failed, r.disabled), (2, 1, 0));
    assert!(r.should_log);
    assert_eq!(r.unlogged_faults, 1);

    let r = d.write_frame(off);
    assert_eq!(r.servos[0].outcome, Outcome::Written);
    assert_eq!((r.written, r.failed), (3, 0));

    for _ in 0..2 {
        let r = d.write_frame(off);
        assert_eq!(r.servos[0].outcome, Outcome::Failed(ErrorKind::Other));
        assert!(!r.should_log, "rate-limited");
    }
    let r = d.write_frame(off);
    assert_eq!(r.servos[0].outcome, Outcome::Disabled(ErrorKind::Other));
    assert_eq!((r.written, r.failed, r.disabled), (2, 1, 1));
    assert!(r.should_log, "a servo switched off is always logged");
    assert_eq!(r.unlogged_faults, 3);

    for _ in 0..2 {
        let r = d.write_frame(off);
        assert_eq!(r.servos[0].outcome, Outcome::Off);
        assert_eq!(r.servos[1].outcome, Outcome::Written);
        assert_eq!(
            (r.written, r.failed, r.disabled, r.should_log),
            (2, 0, 0, false)
        );
    }
    let s = d.stats();
    assert_eq!(s.frames, 8);
    assert_eq!(s.faults, [4, 0, 0]);
    assert_eq!(s.disabled, [true, false, false]);
    done(d);
}

#[test]
fn a_failing_start_is_retried_with_the_next_frame() {
    let pitch = pwm(20_000, &[failing(1500), Transaction::set_duty_cycle(1500)]);
    let ch = || pwm(20_000, &writes(&[1500, 1500]));
    let mut cfg = DriverConfig::DEFAULT;
    cfg.pwm.period = Microseconds(20_000);
    let mut d = FrameDriver::new([pitch, ch(), ch()], params(&cfg));
    let r = d.start();
    assert_eq!((r.written, r.failed), (2, 1));
    let r = d.write_frame(mdeg([9000; 3])); // gain 0 on the first frame: still neutral
    assert_eq!((r.written, r.failed), (3, 0));
    assert_eq!(d.stats().faults, [1, 0, 0]);
    done(d);
}

#[test]
fn fault_logs_are_rate_limited() {
    let mut cfg = direct_config();
    cfg.faults = FaultPolicy {
        disable_after: 1000,
        log_interval: Millis(100),
    }; // 5 frames
    let mut ch = [
        Recorder::new(20_000),
        Recorder::new(20_000),
        Recorder::new(20_000),
    ];
    ch[1].fail_next = 13; // the start frame and frames 1..=12
    let mut d = FrameDriver::new(ch, params(&cfg));
    let mut logged = Vec::new();
    for f in 0..20 {
        let r = if f == 0 {
            d.start()
        } else {
            d.write_frame([Angle::ZERO; 3])
        };
        assert_eq!(r.frame, f);
        if r.should_log {
            logged.push((f, r.unlogged_faults));
        }
    }
    assert_eq!(logged, [(0, 1), (5, 5), (10, 5)]);
    assert_eq!(d.stats().faults, [0, 13, 0]);
    assert_eq!(d.stats().disabled, [false; 3]);
}

#[test]
fn a_servo_that_never_works_is_switched_off_after_k_frames() {
    let mut cfg = direct_config();
    cfg.faults.disable_after = 25;
    let mut ch = [
        Recorder::new(20_000),
        Recorder::new(20_000),
        Recorder::new(20_000),
    ];
    ch[2].fail_next = u32::MAX;
    let mut d = FrameDriver::new(ch, params(&cfg));
    d.start();
    for _ in 0..100 {
        d.write_frame(mdeg([1000, 2000, 3000]));
    }
    let [pitch, roll, yaw] = d.release();
    assert_eq!(pitch.written.len(), 101);
    assert_eq!(roll.written.len(), 101);
    // 25 failed writes (start + 24 frames), then the best-effort duty 0.
    assert_eq!(yaw.written.len(), 26);
    assert_eq!(yaw.written.last(), Some(&0));
}

/// Runs `frames` frames of constant `offsets` and returns the pitch angles (m°).
fn pitch_angles(d: &mut FrameDriver<Recorder>, offsets: [i32; 3], frames: usize) -> Vec<i32> {
    (0..frames)
        .map(|_| d.write_frame(mdeg(offsets)).servos[0].angle.millidegrees())
        .collect()
}

fn recorders() -> [Recorder; 3] {
    [
        Recorder::new(20_000),
        Recorder::new(20_000),
        Recorder::new(20_000),
    ]
}

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

/// Smoothstep reference in floating point.
fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

#[test]
fn motion_fades_in_from_neutral_over_two_seconds() {
    let p = params(&DriverConfig::DEFAULT);
    assert_eq!(p.fade_frames(), 100); // 2 s / 20 ms
    let mut d = FrameDriver::new(recorders(), p);
    d.start();
    let a = pitch_angles(&mut d, [9000, 0, 0], 150);
    assert_eq!(a[0], 0, "the first frame after start is still neutral");
    for (k, &x) in a.iter().enumerate() {
        let want = 9000.0 * smoothstep(k as f64 / 100.0);
        assert!(
            (f64::from(x) - want).abs() <= 1.0,
            "frame {k}: {x} vs {want}"
        );
    }
    assert_eq!(a[50], 4500);
    assert_eq!(a[100..], [9000; 50]);
    // Never a step: at most 1.5 · 9° / 100 frames = 0.135° per frame.
    assert!(a.windows(2).all(|w| w[1] - w[0] <= 136));
    assert_eq!(d.release()[0].written[0], 1500);
}

#[test]
fn stop_fades_out_to_the_neutral_pose_and_holds_it() {
    let mut cfg = DriverConfig::DEFAULT;
    cfg.neutral_pose = mdeg([2000, 0, 0]);
    let mut d = FrameDriver::new(recorders(), params(&cfg));
    d.start();
    pitch_angles(&mut d, [9000, 0, 0], 150);
    assert!(!d.is_stopping());
    d.request_stop();
    assert!(d.is_stopping() && !d.is_stopped());
    let a = pitch_angles(&mut d, [9000, 0, 0], 150);
    assert_eq!(a[0], 11_000);
    assert!(
        a.windows(2).all(|w| w[1] <= w[0] && w[0] - w[1] <= 136),
        "{a:?}"
    );
    assert_eq!(a[100..], [2000; 50]);
    assert!(d.is_stopped());
    // 2° → 22.2 µs → 1522 µs.
    assert_eq!(d.channels_mut()[0].written.last(), Some(&1522));
    d.resume();
    assert!(!d.is_stopped());
    let a = pitch_angles(&mut d, [9000, 0, 0], 101);
    assert_eq!((a[0], a[100]), (2000, 11_000));
}

#[test]
fn stop_during_fade_in_reverses_smoothly() {
    let mut d = FrameDriver::new(recorders(), params(&DriverConfig::DEFAULT));
    d.start();
    let mut a = pitch_angles(&mut d, [9000, 0, 0], 30);
    d.request_stop();
    a.extend(pitch_angles(&mut d, [9000, 0, 0], 40));
    assert!(a.windows(2).all(|w| (w[1] - w[0]).abs() <= 136));
    assert_eq!(*a.last().unwrap(), 0);
    assert!(d.is_stopped());
}

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
        &|c| c.faults.disable_after = 0,
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
            },
        },
        "`servos[pitch].limits`",
    );
    check(
        &|c| c.pwm.period = Microseconds(1900),
        ConfigError::PulseLongerThanPeriod {
            axis: Axis::Pitch,
            max_pulse: Microseconds(2000),
        },
        "`servos[pitch].max_pulse`",
    );
    check(
        &|c| c.neutral_pose[1] = Angle::from_degrees(-20),
        ConfigError::NeutralPoseOutsideLimits {
            axis: Axis::Roll,
            pose: Angle::from_degrees(-20),
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
        ConfigError::AccelBelowResolution { axis: Axis::Yaw },
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

#[test]
fn frame_clock_runs_on_time_without_drift() {
    let mut c = FrameClock::new(20_000, 5).unwrap();
    for k in 0..1000u64 {
        assert_eq!(c.deadline(), 5 + 20_000 * k);
        // Woken a little late every time: no skipping, no drift.
        assert_eq!(
            c.tick(c.deadline() + 19_999),
            FrameTick {
                frame: k,
                skipped: 0
            }
        );
    }
    assert_eq!(c.skipped_total(), 0);
    assert_eq!(c.period(), 20_000);
}

#[test]
fn frame_clock_skips_late_frames_without_a_burst() {
    let mut c = FrameClock::new(100, 0).unwrap();
    assert_eq!(
        c.tick(0),
        FrameTick {
            frame: 0,
            skipped: 0
        }
    );
    // Frame 1 due at 100, served at 200: late by a whole period, frame 1 skipped.
    assert_eq!(
        c.tick(200),
        FrameTick {
            frame: 2,
            skipped: 1
        }
    );
    assert_eq!(c.deadline(), 300);
    // Served at 1350: frames 3..=12 missed, frame 13 played now, next due at 1400.
    assert_eq!(
        c.tick(1350),
        FrameTick {
            frame: 13,
            skipped: 10
        }
    );
    assert_eq!(c.deadline(), 1400);
    assert!(
        c.deadline() > 1350,
        "next deadline lies in the future: no catch-up burst"
    );
    // Early call: plays the due frame.
    assert_eq!(
        c.tick(1390),
        FrameTick {
            frame: 14,
            skipped: 0
        }
    );
    assert_eq!(c.deadline(), 1500);
    assert_eq!(c.skipped_total(), 11);
    // Frame index and time stay in step: frame k is due at k · period.
    assert_eq!(c.deadline(), 15 * 100);
}

#[test]
fn frame_clock_saturates_instead_of_overflowing() {
    assert_eq!(FrameClock::new(0, 0), Err(ZeroPeriod));
    let mut c = FrameClock::new(u64::MAX / 2, u64::MAX - 10).unwrap();
    c.tick(u64::MAX);
    assert_eq!(c.deadline(), u64::MAX);
    let t = c.tick(u64::MAX);
    assert_eq!(t.skipped, 0);
}

mod property {
    use super::*;
    use idle_head::servo::{NanosPerDegree, PwmTiming, ServoCalibration};
    use proptest::prelude::*;

    /// A valid calibration: random neutral, scale, direction and limits, with
    /// pulse limits just wide enough (plus a random margin) to reach the limits.
    fn calibration() -> impl Strategy<Value = ServoCalibration> {
        (
            1200u32..=1800,
            5000u32..=20_000,
            any::<bool>(),
            -40_000i32..=0,
            0i32..=40_000,
            0u32..200,
            0u32..200,
        )
            .prop_map(|(neutral, per_degree, reversed, lo, hi, below, above)| {
                let mut cal = ServoCalibration {
                    neutral: Microseconds(neutral),
                    per_degree: NanosPerDegree(per_degree),
                    direction: if reversed {
                        Direction::Reversed
                    } else {
                        Direction::Normal
                    },
                    min_pulse: Microseconds(0),
                    max_pulse: Microseconds(u32::MAX),
                    limits: AngleRange {
                        min: Angle::from_millidegrees(lo),
                        max: Angle::from_millidegrees(hi),
                    },
                };
                let ends = [
                    cal.raw_pulse_us(cal.limits.min),
                    cal.raw_pulse_us(cal.limits.max),
                ];
                let (p_lo, p_hi) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
                cal.min_pulse = Microseconds((p_lo as u32).min(neutral - 1).saturating_sub(below));
                cal.max_pulse = Microseconds((p_hi as u32).max(neutral + 1) + above);
                cal
            })
    }

    fn limits() -> impl Strategy<Value = MotionLimits> {
        (1u32..=400, 1u32..=20_000).prop_map(|(v, a)| MotionLimits {
            max_speed: DegreesPerSecond(v),
            max_accel: DegreesPerSecondSquared(a),
        })
    }

    prop_compose! {
        fn config()(
            servos in [calibration(), calibration(), calibration()],
            motion in [limits(), limits(), limits()],
            pose in [0.0f64..=1.0, 0.0f64..=1.0, 0.0f64..=1.0],
            fade in 0u32..3000,
            disable_after in 1u16..30,
            frame_us in prop_oneof![Just(20_000u32), Just(10_000), Just(3_000)],
        ) -> DriverConfig {
            let mut cfg = DriverConfig::DEFAULT;
            cfg.frame_period = Microseconds(frame_us);
            cfg.servos = servos;
            cfg.motion = motion;
            for i in 0..3 {
                let l = servos[i].limits;
                let (lo, hi) = (f64::from(l.min.millidegrees()), f64::from(l.max.millidegrees()));
                cfg.neutral_pose[i] = Angle::from_millidegrees((lo + pose[i] * (hi - lo)).round() as i32);
            }
            cfg.fade = Millis(fade);
            cfg.faults.disable_after = disable_after;
            cfg
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// For random loops, calibrations, limits and write errors: every duty
        /// written lies within its servo's pulse range (except the single 0 that
        /// switches a failing servo off), every angle within the axis limits,
        /// and no frame-to-frame change exceeds the speed limit, neither in the
        /// commanded angle nor between two pulses a servo actually received.
        #[test]
        fn duties_stay_in_range_and_speed_is_limited(
            cfg in config(),
            loops in proptest::collection::vec([-60_000i32..60_000, -60_000i32..60_000, -60_000i32..60_000], 1..30),
            loop_ms in 20u32..5000,
            max_duty in prop_oneof![Just(20_000u16), Just(62_500), Just(u16::MAX), Just(999)],
            failures in [proptest::collection::vec(proptest::bool::weighted(0.2), 0..40),
                         proptest::collection::vec(proptest::bool::weighted(0.2), 0..40),
                         proptest::collection::vec(proptest::bool::weighted(0.05), 0..40)],
            stop_at in 0usize..400,
        ) {
            let p = params(&cfg);
            let n = loops.len();
            let axis_loop = |a: usize| loops.iter().map(|s| Angle::from_millidegrees(s[a])).collect::<Vec<_>>();
            let (lp, lr, ly) = (axis_loop(0), axis_loop(1), axis_loop(2));
            let play = Playback::new(Millis(loop_ms), cfg.frame_period, n).unwrap();
            let channels = failures.clone().map(|pattern| Recorder { max_duty, fail_pattern: pattern, ..Recorder::default() });
            let mut d = FrameDriver::new(channels, p);
            let first = d.start().servos.map(|s| s.angle);
            prop_assert_eq!(first, [Angle::ZERO; 3]);
            // Last angle each servo actually received (the neutral pulse at 0°
            // is where the limiter starts, whether or not that write worked).
            // Every commanded angle lies within one frame's speed limit of it.
            let mut received = [Angle::ZERO; 3];
            for frame in 0..300u64 {
                if frame as usize == stop_at {
                    d.request_stop();
                }
                let r = d.write_frame(play.offsets(frame, [lp.as_slice(), lr.as_slice(), ly.as_slice()]));
                for (i, axis) in Axis::ALL.into_iter().enumerate() {
                    let angle = r.servos[i].angle;
                    prop_assert!(cfg.servos[i].limits.contains(angle));
                    let step = (angle.millidegrees() - received[i].millidegrees()).abs();
                    prop_assert!(step <= p.max_step(axis).millidegrees(), "{axis:?}: {step}");
                    if r.servos[i].outcome == Outcome::Written {
                        received[i] = angle;
                    }
                }
            }
            let disabled = d.stats().disabled;
            let timing = PwmTiming::SERVO_50HZ;
            for (i, ch) in d.release().iter().enumerate() {
                let lo = timing.duty(cfg.servos[i].min_pulse, max_duty).0;
                let hi = timing.duty(cfg.servos[i].max_pulse, max_duty).0;
                let (last, rest) = ch.written.split_last().unwrap();
                prop_assert!(rest.iter().all(|w| (lo..=hi).contains(w)), "{i}: {lo}..={hi} {:?}", ch.written);
                prop_assert!((lo..=hi).contains(last) || (disabled[i] && *last == 0));
            }
        }
    }
}

/// The default limits against the real idle loops (motion engine, Table 2 set).
mod idle_loop {
    use super::*;
    use idle_head::motion::{DEFAULT_HEAD, DEFAULT_N, HeadTrajectories, Mdeg16, Trajectory};

    /// Adapter until `Trajectory` implements `LoopSource` itself.
    struct Loop<'a>(&'a Trajectory<Mdeg16, DEFAULT_N>);

    impl LoopSource for Loop<'_> {
        fn len(&self) -> usize {
            DEFAULT_N
        }
        fn angle(&self, index: usize) -> Angle {
            self.0.angle(index)
        }
    }

    fn head() -> HeadTrajectories<Mdeg16, DEFAULT_N> {
        let mut h = HeadTrajectories::new();
        h.generate(&DEFAULT_HEAD).unwrap();
        h
    }

    /// Largest speed (°/s) and acceleration (°/s²) of the played offsets per axis.
    fn extremes(play: &Playback, loops: [&Loop; 3], frames: u64) -> [(f64, f64); 3] {
        let dt = f64::from(play.frame_period().get()) * 1e-6;
        let mut out = [(0.0f64, 0.0f64); 3];
        let at = |k: u64| {
            play.offsets(k, loops)
                .map(|a| f64::from(a.millidegrees()) / 1000.0)
        };
        for k in 1..frames {
            let (a, b, c) = (at(k - 1), at(k), at(k + 1));
            for i in 0..3 {
                out[i].0 = out[i].0.max((c[i] - b[i]).abs() / dt);
                out[i].1 = out[i].1.max((c[i] - 2.0 * b[i] + a[i]).abs() / (dt * dt));
            }
        }
        out
    }

    #[test]
    fn default_loops_are_far_inside_the_default_limits() {
        let h = head();
        let (p, r, y) = (
            Loop(h.axis(Axis::Pitch)),
            Loop(h.axis(Axis::Roll)),
            Loop(h.axis(Axis::Yaw)),
        );
        for loop_ms in [9_000, 18_000, 30_000] {
            let play = Playback::new(Millis(loop_ms), Microseconds(20_000), DEFAULT_N).unwrap();
            let frames = u64::from(loop_ms) / 20;
            let e = extremes(&play, [&p, &r, &y], frames);
            println!(
                "loop {loop_ms} ms: (°/s, °/s²) pitch {:.1?} roll {:.1?} yaw {:.1?}",
                e[0], e[1], e[2]
            );
            if loop_ms >= 18_000 {
                for (speed, accel) in e {
                    assert!(speed < 30.0 && accel < 300.0, "{e:?}");
                }
            }
        }
    }

    #[test]
    fn default_limits_leave_the_idle_loop_untouched() {
        let h = head();
        let (p, r, y) = (
            Loop(h.axis(Axis::Pitch)),
            Loop(h.axis(Axis::Roll)),
            Loop(h.axis(Axis::Yaw)),
        );
        let cfg = DriverConfig::DEFAULT;
        let play = Playback::new(Millis(18_000), cfg.frame_period, DEFAULT_N).unwrap();
        let mut d = FrameDriver::new(
            [
                Recorder::new(20_000),
                Recorder::new(20_000),
                Recorder::new(20_000),
            ],
            params(&cfg),
        );
        d.start();
        // Two loops plus: after the 2 s fade-in, the angles are exactly the loop.
        for k in 0..2000u64 {
            let offsets = play.offsets(k, [&p, &r, &y]);
            let report = d.write_frame(offsets);
            if k >= 100 {
                assert_eq!(report.servos.map(|s| s.angle), offsets, "frame {k}");
            }
        }
    }
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

#[test]
fn after_failed_writes_the_limiter_resumes_from_the_last_pulse_received() {
    let mut cfg = DriverConfig::DEFAULT;
    cfg.fade = Millis(0);
    let mut ch = recorders();
    let mut d = FrameDriver::new(ch, params(&cfg));
    d.start();
    pitch_angles(&mut d, [0; 3], 5);
    d.channels_mut()[0].fail_next = 10;
    // A 15° step while the pitch channel fails for 10 frames: nothing moves.
    let a = pitch_angles(&mut d, [15_000, 0, 0], 10);
    assert!(a.iter().all(|&x| x == 240), "{a:?}"); // the commanded first step, never received
    // Then it starts from 0°, accelerating as if from rest.
    let a = pitch_angles(&mut d, [15_000, 0, 0], 3);
    assert_eq!(a, [240, 720, 1440]);
    ch = d.release();
    // 0.24° → 2.67 µs → 1503 µs (10 failed attempts), then 0.72° → 1508, 1.44° → 1516.
    assert_eq!(ch[0].written[..6], [1500; 6]);
    assert_eq!(ch[0].written[6..16], [1503; 10]);
    assert_eq!(ch[0].written[16..], [1503, 1508, 1516]);
}
