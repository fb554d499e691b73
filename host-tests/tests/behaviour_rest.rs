//! Rest and wake through the frame engine and the driver: the glide to the
//! rest pose, relax, the wake from it and the glance, a gesture while the
//! head rests, a rest turned round, a new pose while resting.

use host_tests::behaviour::{gesture, look};
use host_tests::rig::{Frame, Rig};
use idle_head_core::behaviour::{Applied, BehaviourConfig, LimitMode, RestState};
use idle_head_core::command::{Action, GestureKind, Hold};
use idle_head_core::{Angle, Axis, Millis};

/// The idle limits of the built-in driver, per frame of 20 ms: 60 °/s and
/// 600 °/s².
const IDLE_STEP: i32 = 1200;
const IDLE_TURN: i32 = 240;

fn relaxing() -> BehaviourConfig {
    let mut config = BehaviourConfig::DEFAULT;
    config.rest.relax = true;
    config
}

/// The largest step and change of step of `values`, per frame.
fn steps(values: &[i32]) -> (i32, i32) {
    let step = values
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .max()
        .unwrap_or(0);
    let turn = values
        .windows(3)
        .map(|w| (w[2] - 2 * w[1] + w[0]).abs())
        .max()
        .unwrap_or(0);
    (step, turn)
}

/// Every frame of `frames` within the idle limits on every axis, in the
/// idle mode, and the mixer's offsets followed exactly (the limiter had
/// nothing to flatten).
fn within_idle_limits(frames: &[Frame], what: &str) {
    for axis in Axis::ALL {
        let i = axis.index();
        let angles: Vec<i32> = frames.iter().map(|f| f.angles[i]).collect();
        let (step, turn) = steps(&angles);
        assert!(step <= IDLE_STEP, "{what}: {axis:?} steps {step} m°/frame");
        assert!(turn <= IDLE_TURN, "{what}: {axis:?} turns {turn} m°/frame²");
        for (k, f) in frames.iter().enumerate() {
            assert_eq!(f.modes[i], LimitMode::Idle, "{what}: {axis:?} frame {k}");
            assert_eq!(
                f.angles[i], f.offsets[i],
                "{what}: {axis:?} frame {k} limited"
            );
        }
    }
}

#[test]
fn rest_glides_to_the_pose_within_the_idle_limits_and_holds_it() {
    let mut rig = Rig::new();
    rig.run(300);
    let Applied::Rest(duration) = rig.apply(Action::Rest) else {
        panic!("not a rest")
    };
    assert!(duration >= Millis(3000), "{duration:?}");
    let frames = u64::from(duration.0 / 20);
    rig.run(frames + 200);
    within_idle_limits(&rig.played[299..], "rest");
    // There at the end of the glide, and held exactly: pitch 8° (nose down).
    for f in &rig.played[(300 + frames) as usize..] {
        assert_eq!(f.angles, [8000, 0, 0]);
        assert_eq!(f.rest, RestState::Resting);
        assert!(f.pulses.iter().all(|&p| p > 0), "pulses on without relax");
    }
    // On the way the idle fades out: the pose is approached monotonically
    // only towards the end, but never passed by more than the idle's swing.
    let mid = &rig.played[300 + frames as usize / 2];
    assert_eq!(mid.rest, RestState::Resting);
}

#[test]
fn relaxed_the_pulses_stop_and_a_wake_brings_them_back_softly_from_the_pose() {
    let mut rig = Rig::with(relaxing(), None);
    rig.run(300);
    rig.apply(Action::Rest);
    let rested = rig.run_until(1000, |f| f.pulses == [0; 3]);
    assert!(rested < 1000, "never relaxed");
    let last_pulses = rig.played[rig.played.len() - 2].pulses;
    assert!(last_pulses.iter().all(|&p| p > 0));
    rig.run(250);
    assert!(
        rig.played
            .iter()
            .rev()
            .take(250)
            .all(|f| f.pulses == [0; 3])
    );
    let start = rig.played.len();
    let Applied::Wake(duration) = rig.apply(Action::Wake { toward: None }) else {
        panic!("not a wake")
    };
    // About a second: the idle comes back.
    assert!(
        (Millis(1000)..=Millis(1500)).contains(&duration),
        "{duration:?}"
    );
    rig.run(200);
    let woke = &rig.played[start..];
    // The first pulse after the gap is the last one before it.
    assert_eq!(woke[0].pulses, last_pulses);
    // The wake's first frame is a step in from the pose (the wake starts at
    // the last frame played): a few m°.
    let from_pose = [8000, 0, 0];
    assert!(
        (0..3).all(|i| (woke[0].angles[i] - from_pose[i]).abs() <= 5),
        "{:?}",
        woke[0].angles
    );
    // Then the idle fades back in within the idle limits, never limited:
    // from the last frame at rest on.
    within_idle_limits(&rig.played[start - 1..], "wake");
    let frames = (duration.0 / 20) as usize;
    // Counted from the last frame at rest, where the wake starts.
    assert_eq!(woke[frames - 2].rest, RestState::Waking);
    assert_eq!(woke[frames - 1].rest, RestState::Awake);
    // Awake: the idle itself (the centre at neutral, full gain).
    let mut awake = Rig::with(relaxing(), None);
    awake.run(rig.frame);
    let tail = rig.played.len() - 20;
    assert_eq!(rig.played[tail..], awake.played[tail..]);
}

#[test]
fn a_wake_with_a_direction_glances_there_once_awake_then_returns() {
    let mut rig = Rig::new();
    rig.run(200);
    rig.apply(Action::Rest);
    rig.run(250);
    let start = rig.played.len();
    let Applied::Wake(duration) = rig.apply(Action::Wake {
        toward: Some(Angle::from_degrees(-20)),
    }) else {
        panic!("not a wake")
    };
    rig.run(400);
    let woke = &rig.played[start..];
    let awake = (duration.0 / 20) as usize;
    // No glance before the head is awake: yaw stays near the idle's.
    assert!(woke[..awake].iter().all(|f| f.angles[2].abs() < 10_000));
    // Then yaw goes to −20° (give or take the ducked idle), holds about
    // 2 s, and returns.
    let there: Vec<usize> = (0..woke.len())
        .filter(|&k| (woke[k].angles[2] + 20_000).abs() < 2500)
        .collect();
    let (first, last) = (there[0], *there.last().unwrap());
    assert!(first > awake, "glanced at frame {first}, awake at {awake}");
    let held = last - first;
    assert!((95..=140).contains(&held), "held {held} frames");
    assert!(woke[399].angles[2].abs() < 10_000);
}

#[test]
fn a_glance_past_the_limits_is_clamped_to_them() {
    let mut rig = Rig::new();
    rig.run(200);
    // Awake: the glance at once; yaw's limits are −23°..32°.
    let Applied::Look(glance) = rig.apply(Action::Wake {
        toward: Some(Angle::from_degrees(-60)),
    }) else {
        panic!("not a glance")
    };
    assert!(glance.clamped);
    assert_eq!(glance.yaw, Angle::from_degrees(-23));
    assert_eq!(glance.hold, Hold::Return(Millis(2000)));
    rig.run(200);
    let yaw = rig.axis(Axis::Yaw);
    assert!(yaw.iter().all(|&y| y >= -23_000));
    assert!(yaw.contains(&-23_000) || yaw.iter().any(|&y| y < -21_000));
}

#[test]
fn a_button_pressed_while_the_head_rests_wakes_it_and_plays() {
    let mut rig = Rig::with(relaxing(), None);
    rig.run(200);
    rig.apply(Action::Rest);
    rig.run_until(1000, |f| f.pulses == [0; 3]);
    rig.run(50);
    let start = rig.played.len();
    let last = rig
        .played
        .iter()
        .rev()
        .find(|f| f.pulses != [0; 3])
        .unwrap()
        .pulses;
    // A nod from a button: it wakes the head (pulses back, from the pose)
    // and plays over the wake.
    let Applied::Gesture(nod) = rig.apply(gesture(GestureKind::Nod, Some(6000), None, None)) else {
        panic!("not a nod")
    };
    rig.run(150);
    let woke = &rig.played[start..];
    assert_eq!(woke[0].pulses, last);
    assert_eq!(woke[0].rest, RestState::Waking);
    let pitch: Vec<i32> = woke.iter().map(|f| f.angles[0]).collect();
    // The nod's dips show: pitch goes well below the rest pose's 8° (the dips add to it).
    let frames = (nod.duration.0 / 20) as usize;
    let highest = *pitch[..frames].iter().max().unwrap();
    assert!(highest > 8000 + 4000, "{highest}");
    assert_eq!(woke.last().unwrap().rest, RestState::Awake);
    // A look wakes it too.
    let mut rig = Rig::with(relaxing(), None);
    rig.run(200);
    rig.apply(Action::Rest);
    rig.run_until(1000, |f| f.pulses == [0; 3]);
    rig.apply(look(0, 10_000, None, Some(Hold::Stay)));
    rig.run(100);
    let f = rig.played.last().unwrap();
    assert_eq!(f.rest, RestState::Awake);
    assert!((f.angles[2] - 10_000).abs() < 2500, "{:?}", f.angles);
}

#[test]
fn a_rest_turned_round_midway_never_jumps() {
    for turn in [10, 60, 120] {
        let mut rig = Rig::new();
        rig.run(300);
        rig.apply(Action::Rest);
        rig.run(turn);
        rig.apply(Action::Wake { toward: None });
        rig.run(100);
        rig.apply(Action::Rest);
        rig.run(200);
        within_idle_limits(&rig.played[299..], "turned round");
    }
}

#[test]
fn a_new_pose_while_resting_is_glided_to() {
    let mut rig = Rig::new();
    rig.run(200);
    rig.apply(Action::Rest);
    rig.run(300);
    assert_eq!(rig.played.last().unwrap().angles, [8000, 0, 0]);
    let mut config = BehaviourConfig::DEFAULT;
    config.rest.pose = [-12_000, 5000, 10_000].map(Angle::from_millidegrees);
    let start = rig.played.len();
    rig.head.set_live(&mut rig.driver, &config.live());
    // The new pose at the next rest: `rest` again glides there.
    rig.run(5);
    assert_eq!(rig.played.last().unwrap().angles, [8000, 0, 0]);
    rig.apply(Action::Rest);
    rig.run(300);
    within_idle_limits(&rig.played[start..], "new pose");
    assert_eq!(rig.played.last().unwrap().angles, [-12_000, 5000, 10_000]);
    // A pose past the limits is clamped to them (pitch's are −12°..20°).
    config.rest.pose = [-30_000, 0, 0].map(Angle::from_millidegrees);
    rig.head.set_live(&mut rig.driver, &config.live());
    rig.apply(Action::Rest);
    rig.run(300);
    assert_eq!(rig.played.last().unwrap().angles, [-12_000, 0, 0]);
}

#[test]
fn stop_and_idle_changes_leave_the_rest_alone() {
    let mut rig = Rig::new();
    rig.run(200);
    rig.apply(Action::Rest);
    rig.run(300);
    rig.apply(Action::Idle(false));
    rig.apply(Action::Center { duration: None });
    rig.run(100);
    let f = rig.played.last().unwrap();
    assert_eq!((f.angles, f.rest), ([8000, 0, 0], RestState::Resting));
    // Awake with nothing to do: a wake without a direction is nothing.
    let mut awake = Rig::new();
    awake.run(10);
    assert_eq!(
        awake.apply(Action::Wake { toward: None }),
        Applied::Wake(Millis(0))
    );
}
