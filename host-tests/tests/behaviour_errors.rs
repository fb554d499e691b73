//! Typed errors of the behaviour: bad requests, bad settings, a full
//! command queue. Each names the field, the value and what is allowed.

use idle_head_core::Angle;
use idle_head_core::behaviour::{
    BehaviourConfig, BehaviourError, CommandQueue, MilliHertz, Mixer, QueueFull,
};
use idle_head_core::command::{Action, GestureKind, GestureRequest, Hold, LookRequest, Percent};
use idle_head_core::driver::{DegreesPerSecond, DriverConfig, DriverParams};
use idle_head_core::units::Millis;

use host_tests::behaviour::{default_params as params, gesture};

fn driver() -> DriverParams {
    DriverConfig::DEFAULT.build().unwrap()
}

/// The error `action` gets, and that the mixer is unchanged after it.
fn refused(action: &Action) -> BehaviourError {
    let mut mixer = Mixer::new(params());
    let before = mixer;
    let err = mixer.apply(action).unwrap_err();
    assert_eq!(mixer, before, "a refused action changed the mixer");
    err
}

#[test]
fn gesture_requests() {
    let cases: [(Action, &str); 12] = [
        (
            gesture(GestureKind::Nod, Some(30_000), None, None),
            "nod amplitude 30°: must be in 0.001°..20° (pitch's limits around its neutral pose)",
        ),
        (
            gesture(GestureKind::Nod, Some(-2000), None, None),
            "nod amplitude -2°: must be in 0.001°..20° (pitch's limits around its neutral pose)",
        ),
        (
            gesture(GestureKind::Shake, Some(25_000), None, None),
            "shake amplitude 25°: must be in 0.001°..23° (yaw's limits around its neutral pose)",
        ),
        (
            gesture(GestureKind::Tilt, Some(-15_000), None, None),
            "tilt amplitude -15°: must be in -14°..19° (roll's limits around its neutral pose)",
        ),
        (
            gesture(GestureKind::Nod, None, Some(0), None),
            "nod duration 0 ms: must be in 1..=10000 ms",
        ),
        (
            gesture(GestureKind::Shake, None, Some(60_000), None),
            "shake duration 60000 ms: must be in 1..=10000 ms",
        ),
        (
            // 30 cycles at the default 2.5 Hz take 12 s.
            gesture(GestureKind::Nod, None, None, Some(30)),
            "nod duration 12000 ms: must be in 1..=10000 ms",
        ),
        (
            gesture(GestureKind::Nod, None, None, Some(0)),
            "nod cycles 0: must be in 1..=32",
        ),
        (
            gesture(GestureKind::Shake, None, Some(9000), Some(200)),
            "shake cycles 200: must be in 1..=32",
        ),
        (
            gesture(GestureKind::Tilt, None, None, Some(3)),
            "tilt cycles 3: a tilt has exactly 1",
        ),
        (
            gesture(GestureKind::Nod, Some(3000), Some(900), Some(6)),
            "nod: 6 cycles in 900 ms are 6.666 Hz: at most 4 Hz (at least 1500 ms for 6 cycles)",
        ),
        (
            // 16° dips at 4 Hz: 1.45 · 8° · 2π · 4 Hz = 292 °/s.
            gesture(GestureKind::Nod, Some(16_000), Some(500), Some(2)),
            "nod: needs 292 °/s on pitch: the gesture speed limit is 250 °/s (lower the amplitude or the tempo)",
        ),
    ];
    for (action, text) in cases {
        let err = refused(&action);
        assert_eq!(err.to_string(), text, "{action:?}");
        assert_eq!(err.code(), "range");
    }
    // Acceleration: 7° shakes at 4 Hz need 1.05 · 7° · 2π · 4 Hz = 185 °/s,
    // within the speed limit, but 1.65 · 7° · (2π · 4 Hz)² = 7296 °/s².
    let err = refused(&gesture(
        GestureKind::Shake,
        Some(7000),
        Some(1000),
        Some(4),
    ));
    assert_eq!(
        err.to_string(),
        "shake: needs 7296 °/s² on yaw: the gesture acceleration limit is 5000 °/s² (lower the amplitude or the tempo)"
    );
}

#[test]
fn look_requests() {
    let look = |ms: Option<u32>, hold: Option<Hold>| {
        Action::Look(LookRequest {
            pitch: Angle::ZERO,
            yaw: Angle::from_degrees(10),
            duration: ms.map(Millis),
            hold,
        })
    };
    assert_eq!(
        refused(&look(Some(0), None)).to_string(),
        "look duration 0 ms: must be in 1..=8000 ms"
    );
    assert_eq!(
        refused(&look(Some(20_000), None)).to_string(),
        "look duration 20000 ms: must be in 1..=8000 ms"
    );
    assert_eq!(
        refused(&look(None, Some(Hold::Return(Millis(4_000_000))))).to_string(),
        "look hold 4000000 ms: must be in 0..=3600000 ms"
    );
    assert_eq!(
        refused(&Action::Center {
            duration: Some(Millis(9000))
        })
        .to_string(),
        "center duration 9000 ms: must be in 1..=8000 ms"
    );
}

/// A change to the default settings.
type Change = dyn Fn(&mut BehaviourConfig);

#[test]
fn settings() {
    let d = driver();
    let build = |change: &Change| {
        let mut cfg = BehaviourConfig::DEFAULT;
        change(&mut cfg);
        cfg.build(&d).map(|_| ()).unwrap_err()
    };
    let cases: [(&Change, &str); 8] = [
        (
            &|c| c.max_frequency = MilliHertz(9000),
            "behaviour config `max_frequency` = 9000 mHz: must be in 500..=6250 mHz",
        ),
        (
            &|c| c.blend = Millis(0),
            "behaviour config `blend` = 0 ms: must be in 20..=2000 ms",
        ),
        (
            &|c| c.gaze.hold = Hold::Return(Millis(u32::MAX)),
            "behaviour config `gaze.hold` = 4294967295 ms: must be in 0..=3600000 ms",
        ),
        (
            &|c| c.gesture_limits[2].max_speed = DegreesPerSecond(30),
            "behaviour config `gesture_limits[yaw].max_speed` = 30 °/s: must be in 60..=2000 °/s",
        ),
        (
            &|c| c.defaults_mut(GestureKind::Nod).slow = MilliHertz(5000),
            "behaviour config `nod.slow` = 5000 mHz: must be in 100..=3500 mHz",
        ),
        (
            &|c| c.defaults_mut(GestureKind::Shake).brisk = MilliHertz(4500),
            "behaviour config `shake.brisk` = 4500 mHz: must be in 1200..=4000 mHz",
        ),
        (
            &|c| c.defaults_mut(GestureKind::Tilt).cycles = 0,
            "behaviour config `tilt.cycles` = 0 cycles: must be in 1..=32 cycles",
        ),
        (
            // The default nod at 100 % (amplitude × 1.25 × 1.05) leaves pitch.
            &|c| c.defaults_mut(GestureKind::Nod).amplitude = Angle::from_degrees(18),
            "nod amplitude 23.625°: must be in 0.001°..20° (pitch's limits around its neutral pose)",
        ),
    ];
    for (change, text) in cases {
        let err = build(change);
        assert_eq!(err.to_string(), text);
    }
    let err = build(&|c| c.idle.fade = Millis(50_000));
    assert_eq!(err.code(), "config");
    assert_eq!(err.message(), "behaviour config value out of range");
    assert!(matches!(
        err,
        BehaviourError::Config {
            field: "idle.fade",
            ..
        }
    ));
    // The idle mode is the driver's: a driver with brisker limits raises the
    // floor of the gesture limits.
    let mut brisk = DriverConfig::DEFAULT;
    brisk.motion[0].max_speed = DegreesPerSecond(400);
    let err = BehaviourConfig::DEFAULT
        .build(&brisk.build().unwrap())
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "behaviour config `gesture_limits[pitch].max_speed` = 250 °/s: must be in 400..=2000 °/s"
    );
    // A neutral pose near a limit leaves less room for a nod.
    let mut posed = DriverConfig::DEFAULT;
    posed.neutral_pose[0] = Angle::from_degrees(16);
    let params = BehaviourConfig::DEFAULT.build(&posed.build().unwrap());
    assert!(
        matches!(params, Err(BehaviourError::Amplitude { .. })),
        "{params:?}"
    );
}

#[test]
fn every_default_gesture_plays_at_every_intensity() {
    let params = params();
    for kind in [GestureKind::Nod, GestureKind::Shake, GestureKind::Tilt] {
        for p in 0..=100 {
            let request = GestureRequest {
                intensity: Percent::new(p),
                ..GestureRequest::new(kind)
            };
            let mut mixer = Mixer::new(params);
            assert!(
                mixer.apply(&Action::Gesture(request)).is_ok(),
                "{kind:?} at {p} %"
            );
        }
    }
}

#[test]
fn a_full_queue_hands_the_action_back() {
    let queue: CommandQueue<3> = CommandQueue::new();
    let actions = [
        Action::Stop,
        Action::Idle(true),
        gesture(GestureKind::Nod, None, None, None),
    ];
    for action in actions {
        queue.try_submit(action).unwrap();
    }
    let extra = Action::IdleAmp(Percent::HALF);
    let err = queue.try_submit(extra).unwrap_err();
    assert_eq!(err, QueueFull(extra));
    assert_eq!(
        err.to_string(),
        "command queue full: try again after the next frame"
    );
    // Nothing was dropped: the three come out in order, then there is room.
    assert_eq!(queue.len(), 3);
    for action in actions {
        assert_eq!(queue.take(), Some(action));
    }
    assert_eq!(queue.take(), None);
    queue.try_submit(extra).unwrap();
}
