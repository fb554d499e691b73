//! The reply to a queued action, once the frame task has taken or
//! refused it: one text for the firmware's ports and for every host tool
//! that predicts the replies (the simulated head of the host tests, the
//! emulator's expected transcript).
//!
//! ```text
//! nod           →  ok nod amp_mdeg=8000 ms=1200 cycles=2 intensity=50
//! look 5000 0   →  ok look pitch=5000 yaw=0 ms=420 hold=2000
//! center        →  ok center ms=300
//! idle amp 60   →  ok idle=60
//! stop          →  ok stopping
//! shake         →  err busy gestures: every layer is busy; try again in 180 ms
//! ```

use crate::behaviour::{Applied, BehaviourError};
use crate::command::Hold;
use crate::text::Arg::{Int, Str, Uint};
use crate::text::Text;

use super::reply::{ErrorCode, Reply};

/// Writes the reply to an action the frame task took (what it started,
/// in the protocol's units) or refused (the mixer's error: `err busy …`
/// with the time to try again).
pub fn outcome_reply(reply: &mut Reply<'_>, result: &Result<Applied, BehaviourError>) {
    match result {
        Ok(applied) => started(reply, applied),
        Err(e) => {
            let text: &mut dyn Text = reply.err(behaviour_code(e));
            text.with(e);
        }
    }
}

/// Writes the reply to an action no frame took within `waited_ms`: the
/// frame task is not running (the head's frames stopped). The action
/// stays queued and plays if the frames start again.
pub fn unanswered(reply: &mut Reply<'_>, waited_ms: u32) {
    let text: &mut dyn Text = reply.err(ErrorCode::State);
    text.fill(
        "no frame took the command within {} ms: the frames are not running",
        &[Uint(waited_ms.into())],
    );
}

fn started(reply: &mut Reply<'_>, applied: &Applied) {
    let text: &mut dyn Text = reply.ok();
    match applied {
        Applied::Gesture(plan) => {
            text.fill(
                "{} amp_mdeg={} ms={} cycles={} intensity={}",
                &[
                    Str(plan.kind.name()),
                    Int(plan.amplitude.millidegrees().into()),
                    Uint(plan.duration.0.into()),
                    Uint(plan.cycles.into()),
                    Uint(plan.intensity.get().into()),
                ],
            );
        }
        Applied::Look(look) => {
            text.fill(
                "look pitch={} yaw={} ms={} hold=",
                &[
                    Int(look.pitch.millidegrees().into()),
                    Int(look.yaw.millidegrees().into()),
                    Uint(look.duration.0.into()),
                ],
            );
            match look.hold {
                Hold::Return(after) => text.u64(after.0.into()),
                Hold::Stay => text.str("stay"),
            };
            if look.clamped {
                text.str(" clamped");
            }
        }
        Applied::Center(duration) => {
            text.str("center ms=").u64(duration.0.into());
        }
        Applied::Idle(gain) => {
            text.str("idle=").u64(gain.get().into());
        }
        Applied::Stop => {
            text.str("stopping");
        }
        Applied::Rest(duration) => {
            text.str("rest ms=").u64(duration.0.into());
        }
        Applied::Wake(duration) => {
            text.str("wake ms=").u64(duration.0.into());
        }
    }
}

/// The reply code of a refused motion.
pub(super) const fn behaviour_code(e: &BehaviourError) -> ErrorCode {
    match e {
        BehaviourError::Busy { .. } => ErrorCode::Busy,
        BehaviourError::Amplitude { .. } => ErrorCode::Limit,
        BehaviourError::Config { .. } => ErrorCode::Invalid,
        _ => ErrorCode::Range,
    }
}
