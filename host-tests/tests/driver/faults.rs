//! PWM write errors: counted, logged at a limited rate, retried, and a servo
//! that keeps failing switched off; the limiter resumes from the last pulse
//! a servo received.

use embedded_hal::pwm::ErrorKind;
use embedded_hal_mock::eh1::pwm::Transaction;
use host_tests::{Recorder, direct_config, failing, mdeg, params, pwm, writes};
use idle_head_core::driver::{DriverConfig, FaultPolicy, FrameDriver, Outcome};
use idle_head_core::servo::Duty;
use idle_head_core::{Angle, Microseconds, Millis};

use super::{done, pitch_angles, recorders};

#[test]
fn a_write_error_is_counted_others_keep_moving_and_it_is_retried() {
    let mut cfg = direct_config();
    cfg.faults.disable_after = Millis(60); // 3 frames
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
        disable_after: Millis(20_000),
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
    cfg.faults.disable_after = Millis(500); // 25 frames
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
