//! The smoke run's behaviour script: gestures and a look over the
//! never-repeating idle, submitted to the frame task's command queue as a
//! console or a show controller would.
//!
//! Frames are the Pico's 50 Hz frames one for one (see the crate docs), so
//! the script reads in board time: a nod 2 s in, a shake at 6 s that a tilt
//! interrupts 0.8 s later, then a look at 12 s held for 1.5 s and its
//! return, all before the first join (frame 1400, 28 s) so that the join's
//! smoothness check sees the idle alone. The frame task logs every command
//! with its answer (`frame <n>: <action>: ok <what it started>`).

use idle_head_core::behaviour::{CommandQueue, QueueFull};
use idle_head_core::command::{Action, GestureKind, GestureRequest, Hold, LookRequest};
use idle_head_core::units::{Angle, Millis};

/// One scripted command: the frame it is submitted before, and the action.
pub struct Step {
    pub frame: u64,
    pub action: Action,
}

/// The script, in frame order.
pub const SCRIPT: [Step; 4] = [
    Step {
        frame: 100,
        action: Action::Gesture(GestureRequest::new(GestureKind::Nod)),
    },
    Step {
        frame: 300,
        action: Action::Gesture(GestureRequest::new(GestureKind::Shake)),
    },
    // Into the shake's second cycle: the shake fades out under the tilt.
    Step {
        frame: 340,
        action: Action::Gesture(GestureRequest::new(GestureKind::Tilt)),
    },
    // Up and to the left, held 1.5 s, then back to the centre.
    Step {
        frame: 600,
        action: Action::Look(LookRequest {
            pitch: Angle::from_degrees(6),
            yaw: Angle::from_degrees(-18),
            duration: None,
            hold: Some(Hold::Return(Millis(1500))),
        }),
    },
];

/// The last frame the script's motion may still play in: the look's move
/// (about 0.5 s), its hold and its return end well before this.
pub const QUIET_FROM: u64 = 900;

const _: () = {
    let mut i = 1;
    while i < SCRIPT.len() {
        assert!(
            SCRIPT[i - 1].frame < SCRIPT[i].frame,
            "script in frame order"
        );
        i += 1;
    }
    assert!(SCRIPT[SCRIPT.len() - 1].frame < QUIET_FROM);
};

/// Submits the steps due before `frame`; a full queue is an error (the
/// script never sends more than one command a frame).
pub fn submit(frame: u64, queue: &CommandQueue) -> Result<(), QueueFull> {
    for step in SCRIPT.iter().filter(|step| step.frame == frame) {
        queue.try_submit(step.action)?;
    }
    Ok(())
}
