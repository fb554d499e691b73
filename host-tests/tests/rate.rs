//! The servos' rate (`servo rate`): the motion is the same in time at 50,
//! 200 and 333 Hz (idle loops and their joins, gestures, looks and their
//! returns, rest and wake, idle changes, the fade), the limits hold in °/s
//! and °/s² at every rate, and a change of rate between two frames goes on
//! with the motion without a jump, the outputs taking the new period at
//! the frame the rig says.

use host_tests::behaviour::{gesture, look};
use host_tests::rig::{Frame, Rig, assert_physical_limits};
use idle_head_core::behaviour::BehaviourConfig;
use idle_head_core::command::{Action, GestureKind, GestureRequest, Hold, Percent};
use idle_head_core::servo::ServoRate;
use idle_head_core::units::Millis;

/// Times at which the frames of 50, 200 and 333 Hz (20 000, 5000 and 3003
/// µs) meet: every 60.06 s (their least common multiple).
const MEET: u64 = 60_060_000;

fn rate(hz: u16) -> ServoRate {
    ServoRate::new(hz).unwrap()
}

/// An action the script starts at a time.
struct Step {
    /// When the action starts, µs.
    at: u64,
    action: Action,
}

/// Plays `script` at `hz` until `until` µs, each action applied so that it
/// starts at its time (which is a frame at every rate: 0 or a multiple of
/// [`MEET`]); every frame played.
fn play(hz: u16, script: &[Step], until: u64) -> Vec<Frame> {
    let mut rig = Rig::at_rate(BehaviourConfig::DEFAULT, None, rate(hz));
    let period = u64::from(rate(hz).period().0);
    let mut played = vec![false; script.len()];
    while rig.at < until {
        for (step, done) in script.iter().zip(&mut played) {
            // An action starts at the last frame mixed: applied before the
            // frame after the one it starts at (before the first, at 0).
            let due = if step.at > 0 {
                step.at + period
            } else {
                step.at
            };
            if !*done && rig.at == due {
                rig.apply(step.action);
                *done = true;
            }
        }
        rig.run(1);
    }
    assert!(played.iter().all(|&p| p), "every step played");
    rig.played
}

/// The angles of `frames` at `t` µs, linearly between the frames around it.
fn angles_at(frames: &[Frame], t: u64) -> [f64; 3] {
    let k = frames.partition_point(|f| f.at <= t) - 1;
    let (a, b) = (&frames[k], &frames[(k + 1).min(frames.len() - 1)]);
    let w = if b.at == a.at {
        0.0
    } else {
        (t - a.at) as f64 / (b.at - a.at) as f64
    };
    core::array::from_fn(|i| f64::from(a.angles[i]) + w * f64::from(b.angles[i] - a.angles[i]))
}

/// The largest difference in m° between `frames` and the 50 Hz `reference`
/// at the reference's frames (those of `frames` interpolated).
fn largest_difference(reference: &[Frame], frames: &[Frame]) -> f64 {
    let mut worst = (0.0, 0, 0);
    for f in reference {
        let at = angles_at(frames, f.at);
        for (i, (got, want)) in at.iter().zip(f.angles).enumerate() {
            let d = (got - f64::from(want)).abs();
            if d > worst.0 {
                worst = (d, f.at, i);
            }
        }
    }
    if worst.0 > 0.0 {
        println!("  largest at {} µs, axis {}", worst.1, worst.2);
    }
    worst.0
}

/// The script: idle all along (joins at 28 s, 56 s …), a look with a hold
/// and its return and a nod at once from the start (over the fade-in); a
/// brisk shake and an idle change; a look and a tilt; a rest (which moves
/// the gaze back to the centre); a wake. Nothing moves past the limits,
/// so the limiter follows the motion as it is (its own test is below).
fn script() -> Vec<Step> {
    let brisk = GestureRequest {
        intensity: Some(Percent::new(80).unwrap()),
        ..GestureRequest::new(GestureKind::Shake)
    };
    vec![
        Step {
            at: 0,
            action: look(10_000, -20_000, None, Some(Hold::Return(Millis(1500)))),
        },
        Step {
            at: 0,
            action: gesture(GestureKind::Nod, None, None, None),
        },
        Step {
            at: MEET,
            action: Action::Gesture(brisk),
        },
        Step {
            at: MEET,
            action: Action::IdleAmp(Percent::new(40).unwrap()),
        },
        Step {
            at: 2 * MEET,
            action: look(-5000, 25_000, Some(Millis(700)), Some(Hold::Stay)),
        },
        Step {
            at: 2 * MEET,
            action: gesture(GestureKind::Tilt, Some(-9000), Some(1500), None),
        },
        Step {
            at: 3 * MEET,
            action: Action::Rest,
        },
        Step {
            at: 4 * MEET,
            action: Action::Wake { toward: None },
        },
    ]
}

#[test]
fn the_motion_is_the_same_in_time_at_50_200_and_333_hz() {
    let script = script();
    let until = 4 * MEET + 4_000_000;
    let reference = play(50, &script, until);
    for hz in [200, 333] {
        let frames = play(hz, &script, until);
        let worst = largest_difference(&reference, &frames);
        println!("{hz} Hz against 50 Hz: at most {worst:.2} m° apart");
        // The angles of two rates differ only by the m° each frame rounds
        // to and, at 333 Hz, the straight line drawn between its frames
        // (a·dt²/8: 5 m° at the gesture limits' 5000 °/s²).
        assert!(worst <= 6.0, "{hz} Hz: {worst} m° from the 50 Hz frames");
        let params = *Rig::at_rate(BehaviourConfig::DEFAULT, None, rate(hz))
            .head
            .mixer()
            .params();
        assert_physical_limits(&params, &frames);
    }
    // The moves are there: the look holds its target (the idle ducked
    // under it), the rest arrives at its pose.
    let held = reference.iter().find(|f| f.at == 1_500_000).unwrap();
    assert!((held.offsets[0] - 10_000).abs() < 1500, "{held:?}");
    let pitch = |t: u64| angles_at(&reference, t)[0];
    assert!((pitch(3 * MEET + 9_000_000) - 8000.0).abs() < 100.0);
}

/// The frame driver alone at `hz`, its target jumping and swinging far
/// beyond the idle limits (steps of 25°, a 3 Hz swing of 15°), the rate
/// changed to each of `changes` at their times (µs): every frame as the
/// rig records it.
fn limited(hz: u16, changes: &[(u64, u16)], until: u64) -> (Vec<Frame>, Vec<(usize, u32)>) {
    use idle_head_core::behaviour::{IdleSource, LimitMode};
    use idle_head_core::{Angle, Timestamp};

    /// The target: a square wave of ±25° every 0.7 s on pitch, a 3 Hz
    /// swing of 15° on yaw, still on roll.
    struct Harsh;
    impl IdleSource for Harsh {
        fn offsets(&mut self, at: Timestamp) -> [Angle; 3] {
            let t = at.0 as f64 / 1e6;
            let square = if (at.0 / 700_000).is_multiple_of(2) {
                10_000
            } else {
                -10_000
            };
            let swing = (15_000.0 * (std::f64::consts::TAU * 3.0 * t).sin()) as i32;
            [square, 0, swing].map(Angle::from_millidegrees)
        }
    }

    let mut rig = Rig::at_rate(BehaviourConfig::DEFAULT, None, rate(hz));
    let behaviour = *rig.head.mixer().params();
    let mut head = idle_head_core::behaviour::Head::new(Harsh, behaviour);
    let mut frames = Vec::new();
    let (mut at, mut next_change) = (0, 0);
    let mut pending = None;
    while at < until {
        if let Some(&(when, hz)) = changes.get(next_change)
            && at >= when
        {
            pending = Some(rate(hz).period());
            next_change += 1;
        }
        if let Some(period) = pending {
            rig.driver.set_pwm_period(period).unwrap();
        }
        let played = head.frame(&mut rig.driver, Timestamp(at));
        if let Some(period) = pending.take() {
            head.set_frame_period(&mut rig.driver, period).unwrap();
        }
        frames.push(Frame {
            at,
            offsets: played.offsets.map(Angle::millidegrees),
            angles: played.report.servos.map(|s| s.angle.millidegrees()),
            pulses: played.report.servos.map(|s| s.pulse.0),
            modes: [LimitMode::Idle; 3],
            rest: idle_head_core::behaviour::RestState::Awake,
        });
        at += u64::from(rig.driver.params().config().frame_period.0);
    }
    let periods = rig.driver.channels_mut()[0].periods.clone();
    (frames, periods)
}

#[test]
fn the_limits_hold_in_degrees_per_second_at_every_rate() {
    let params = *Rig::new().head.mixer().params();
    for hz in [50, 200, 333] {
        let (frames, _) = limited(hz, &[], 8_000_000);
        assert_physical_limits(&params, &frames);
        // The limits are met, not merely respected: the swing is slowed to
        // the idle limit's 60 °/s (a step of 60 °/s · period).
        let period = f64::from(rate(hz).period().0);
        let fastest = frames
            .windows(2)
            .map(|w| (w[1].angles[2] - w[0].angles[2]).abs())
            .max()
            .unwrap();
        let limit = 60.0 * period / 1000.0;
        assert!(
            f64::from(fastest) >= limit - 1.0,
            "{hz} Hz: {fastest} m° a frame, the limit {limit}"
        );
    }
}

#[test]
fn a_change_of_rate_keeps_the_limits_across_it() {
    let params = *Rig::new().head.mixer().params();
    // Mid-swing and mid-step: up, down, up again, back to 50 Hz.
    let changes = [
        (1_010_000, 333),
        (2_333_333, 200),
        (3_500_000, 333),
        (4_600_000, 50),
    ];
    let (frames, periods) = limited(50, &changes, 7_000_000);
    assert_physical_limits(&params, &frames);
    // The outputs took each period before the frame after its change: the
    // frames after it come that far apart.
    assert_eq!(periods.len(), changes.len());
    for ((written, period), (when, hz)) in periods.iter().zip(changes) {
        let boundary = &frames[*written];
        assert!(boundary.at >= when, "{boundary:?}");
        assert_eq!(*period, rate(hz).period().0);
        let after = frames[*written + 1].at - boundary.at;
        assert_eq!(after, u64::from(*period), "the frame after the boundary");
    }
}

#[test]
fn a_change_of_rate_goes_on_with_the_motion_as_it_was() {
    // The idle, a nod, a look and its return; the rate changed while they
    // play: the same angles at the same times as at 50 Hz all along.
    let script = [
        Step {
            at: 0,
            action: look(8000, -15_000, None, Some(Hold::Return(Millis(1200)))),
        },
        Step {
            at: 0,
            action: gesture(GestureKind::Nod, None, Some(2000), Some(4)),
        },
    ];
    let reference = play(50, &script, 6_000_000);
    let mut rig = Rig::new();
    for step in &script {
        rig.apply(step.action);
    }
    for (until, hz) in [
        (700_000, 333),
        (1_401_000, 200),
        (2_600_000, 333),
        (4_000_000, 50),
        (6_000_000, 50),
    ] {
        while rig.at < until {
            rig.run(1);
        }
        rig.set_rate(rate(hz));
    }
    let worst = largest_difference(&reference, &rig.played);
    println!("rate changes against 50 Hz all along: at most {worst:.2} m° apart");
    assert!(worst <= 6.0, "{worst} m° from the 50 Hz frames");
    assert_physical_limits(rig.head.mixer().params(), &rig.played);
    // The recorders saw each period at the frame after its change.
    let periods: Vec<u32> = rig.driver.channels_mut()[0]
        .periods
        .iter()
        .map(|p| p.1)
        .collect();
    assert_eq!(periods, [3003, 5000, 3003, 20_000]);
}

/// `servo rate` checks the settings in effect at the new rate with
/// `Settings::validate_rate`, which skips the gestures' plans: it must
/// answer as the full `validate` does, at every rate, for settings the
/// rate leaves valid and for settings it makes invalid (a frequency cap
/// only the faster rates allow, gesture limits beyond the idle's).
#[test]
fn a_change_of_rate_is_checked_as_the_full_settings() {
    use idle_head_core::driver::DriverConfig;
    use idle_head_core::settings::Settings;
    use idle_head_core::units::{DegreesPerSecond, MilliHertz};
    let base = DriverConfig::DEFAULT;
    let mut fast_cap = Settings::DEFAULT;
    // 8 frames a cycle: 6250 mHz at 50 Hz, 41 625 at 333 Hz.
    fast_cap.behaviour.max_frequency = MilliHertz(10_000);
    let mut brisk = Settings::DEFAULT;
    brisk.behaviour.gesture_limits[2].max_speed = DegreesPerSecond(1999);
    let mut refused = Settings::DEFAULT;
    refused.behaviour.gesture_limits[0].max_speed = DegreesPerSecond(1);
    let (mut valid, mut invalid) = (0, 0);
    for settings in [Settings::DEFAULT, fast_cap, brisk, refused] {
        for hz in ServoRate::MIN.hz()..=ServoRate::MAX.hz() {
            let mut next = settings;
            next.rate = rate(hz);
            let full = next.validate(&base);
            assert_eq!(next.validate_rate(&base), full, "{hz} Hz");
            if full.is_ok() {
                valid += 1
            } else {
                invalid += 1
            }
        }
    }
    // Both answers were seen.
    assert!(valid > 0 && invalid > 0, "{valid} valid, {invalid} invalid");
}
