//! Any commands at any frames: the head stays inside every safety stage and
//! never panics.

use proptest::prelude::*;

use super::{Rig, assert_safe};
use host_tests::behaviour::look;
use idle_head_core::command::{Action, GestureKind, GestureRequest, Hold, Percent};
use idle_head_core::units::{Angle, Millis};

fn kind() -> impl Strategy<Value = GestureKind> {
    prop::sample::select(GestureKind::ALL.to_vec())
}

/// Commands, valid or not (amplitudes past the limits, absurd durations).
fn action() -> impl Strategy<Value = Action> {
    let millis = prop::option::of((1_u32..12_000).prop_map(Millis));
    prop_oneof![
        4 => (
            kind(),
            prop::option::of(-30_000_i32..30_000),
            millis.clone(),
            prop::option::of(0_u8..12),
            prop::option::of(0_u8..=100),
        )
            .prop_map(|(kind, amplitude, duration, cycles, intensity)| {
                Action::Gesture(GestureRequest {
                    kind,
                    amplitude: amplitude.map(Angle::from_millidegrees),
                    duration,
                    cycles,
                    intensity: intensity.and_then(Percent::new),
                })
            }),
        3 => (
            -40_000_i32..40_000,
            -60_000_i32..60_000,
            millis.clone(),
            prop::option::of(prop_oneof![
                Just(Hold::Stay),
                (0_u32..5000).prop_map(|ms| Hold::Return(Millis(ms)))
            ]),
        )
            .prop_map(|(pitch, yaw, duration, hold)| look(pitch, yaw, duration, hold)),
        1 => millis.prop_map(|duration| Action::Center { duration }),
        1 => any::<bool>().prop_map(Action::Idle),
        1 => (0_u8..=100).prop_map(|p| Action::IdleAmp(Percent::new(p).unwrap_or(Percent::FULL))),
        1 => Just(Action::Stop),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(host_tests::cases(64)))]

    #[test]
    fn any_commands_stay_inside_the_safety_stages(
        script in prop::collection::vec((0_u64..40, action()), 1..12)
    ) {
        let mut rig = Rig::new();
        rig.run(100);
        for (wait, action) in script {
            rig.run(wait);
            // Refused or applied, never a panic.
            let _ = rig.head.apply(&mut rig.driver, &action);
        }
        rig.run(150);
        assert_safe(&rig);
    }
}
