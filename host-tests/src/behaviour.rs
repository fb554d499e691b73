//! Shared helpers for the behaviour tests.

use idle_head_core::behaviour::{BehaviourConfig, BehaviourParams};
use idle_head_core::command::{Action, GestureKind, GestureRequest, Hold, LookRequest};
use idle_head_core::driver::DriverConfig;
use idle_head_core::units::Millis;
use idle_head_core::{Angle, Timestamp};

/// The built-in behaviour on the built-in driver configuration (panics if
/// either is invalid: tests only).
#[must_use]
pub fn default_params() -> BehaviourParams {
    let driver = DriverConfig::DEFAULT.build().unwrap();
    BehaviourConfig::DEFAULT.build(&driver).unwrap()
}

/// The time of frame `k` at the built-in 50 Hz (20 ms frames).
#[must_use]
pub const fn frame(k: u64) -> Timestamp {
    Timestamp(k * 20_000)
}

/// A gesture request of `kind`: amplitude in m°, duration in ms and cycles
/// as given (`None`: the default), at the default intensity.
#[must_use]
pub fn gesture(kind: GestureKind, amp: Option<i32>, ms: Option<u32>, cycles: Option<u8>) -> Action {
    Action::Gesture(GestureRequest {
        kind,
        amplitude: amp.map(Angle::from_millidegrees),
        duration: ms.map(Millis),
        cycles,
        intensity: None,
    })
}

/// A look at `pitch` and `yaw` (m°), with the duration and the hold as
/// given (`None`: the default).
#[must_use]
pub fn look(pitch: i32, yaw: i32, duration: Option<Millis>, hold: Option<Hold>) -> Action {
    Action::Look(LookRequest {
        pitch: Angle::from_millidegrees(pitch),
        yaw: Angle::from_millidegrees(yaw),
        duration,
        hold,
    })
}
