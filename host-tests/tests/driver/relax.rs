//! Relax: the pulses stop (duty 0) with the limiter held where it was, and
//! come back from there.

use host_tests::{mdeg, params};
use idle_head_core::Millis;
use idle_head_core::driver::{DriverConfig, FrameDriver, Outcome};

use super::{angles, duties, pitch_angles, recorders};

#[test]
fn relaxed_frames_write_duty_0_and_the_pulses_come_back_where_they_stopped() {
    let mut d = FrameDriver::new(recorders(), params(&DriverConfig::DEFAULT));
    // Before the start there is nothing to relax: the first frame is still
    // the neutral pulse.
    d.set_relaxed(true);
    assert!(!d.is_relaxed());
    d.start();
    let a = pitch_angles(&mut d, [-8000, 0, 0], 200);
    assert_eq!(a[199], -8000);
    let before = d.channels_mut()[0].written.last().copied();
    d.set_relaxed(true);
    assert!(d.is_relaxed());
    for _ in 0..50 {
        // Whatever is asked meanwhile: no pulse, the angle held.
        let r = d.write_frame(mdeg([5000, 3000, -2000]));
        assert_eq!(duties(&r), [0; 3]);
        assert!(
            r.servos
                .iter()
                .all(|s| s.pulse.0 == 0 && s.outcome == Outcome::Written)
        );
        assert_eq!(angles(&r)[0], -8000);
    }
    assert_eq!(
        d.channels_mut()[0].written.iter().rev().take(50).max(),
        Some(&0)
    );
    assert_eq!(d.angles()[0].millidegrees(), -8000);
    d.set_relaxed(false);
    // The first pulse after the gap is the last one before it; then the head
    // moves on within the limits (60 °/s, 600 °/s²: 0.24° a frame more each
    // frame at most).
    let r = d.write_frame(mdeg([-8000, 0, 0]));
    assert_eq!(Some(duties(&r)[0]), before);
    let a = pitch_angles(&mut d, [4000, 0, 0], 200);
    let mut last = (-8000, 0);
    for (k, &x) in a.iter().enumerate() {
        let step = x - last.0;
        assert!(
            step.abs() <= 1200 && (step - last.1).abs() <= 241,
            "frame {k}: {x}"
        );
        last = (x, step);
    }
    assert_eq!(a[199], 4000);
}

#[test]
fn a_servo_switched_off_stays_off_when_relaxed() {
    let mut rec = recorders();
    rec[2].fail_next = 1000;
    let mut cfg = DriverConfig::DEFAULT;
    cfg.faults.disable_after = Millis(60); // 3 frames
    let mut d = FrameDriver::new(rec, params(&cfg));
    d.start();
    pitch_angles(&mut d, [0; 3], 10);
    assert!(d.stats().disabled[2]);
    let writes = d.channels_mut()[2].written.len();
    d.set_relaxed(true);
    let r = d.write_frame(mdeg([0; 3]));
    assert_eq!(r.servos[2].outcome, Outcome::Off);
    assert_eq!(d.channels_mut()[2].written.len(), writes);
}

#[test]
fn after_frames_missed_the_servos_start_again_from_rest() {
    // A head moving at speed, then frames missed (the PWM held the last
    // pulses: the servos stood still), then the target far on.
    let mut d = FrameDriver::new(recorders(), params(&DriverConfig::DEFAULT));
    d.start();
    let ramp: Vec<i32> = (0..100).map(|k| k * 200).collect();
    let mut last = 0;
    for &x in &ramp {
        last = angles(&d.write_frame(mdeg([x, 0, 0])))[0];
    }
    d.held();
    // From rest: the first step is within one frame's acceleration (0.24°
    // a frame, a frame), never the speed it had before the gap.
    let mut step_before = 0;
    for k in 0..40 {
        let x = angles(&d.write_frame(mdeg([25_000, 0, 0])))[0];
        let step = x - last;
        assert!(
            (step - step_before).abs() <= 241 && step.abs() <= 1200,
            "frame {k} after the gap: {last} → {x}"
        );
        (last, step_before) = (x, step);
    }
}
