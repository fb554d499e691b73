//! The console's handler until the settings service takes its place.
//!
//! `help`, the motion commands into the frame task's queue (a full queue is
//! `err busy`, the command not taken), `err state not available yet` for
//! the commands that need the settings service. Free of the board: the
//! emulator check (`cargo xtask sim`) compiles this file on the host and
//! computes the replies it expects with it.

use core::fmt::Write as _;

use idle_head::behaviour::CommandQueue;
use idle_head::command::Command;
use idle_head::console::{ErrorCode, HELP, Handler, Reply, Session};

/// A console session on the Pico: lines up to 96 bytes, replies up to 160,
/// as `docs/protocol.md` promises.
pub type PicoSession = Session<96, 160>;

/// The console's command queue, drained by the frame task.
pub type Queue = CommandQueue;

/// The console's handler until the settings service takes over: `help`,
/// motion commands into the frame task's queue, `err state` for the rest.
pub struct QueueHandler {
    queue: &'static Queue,
}

impl QueueHandler {
    /// A handler queueing actions into `queue`.
    pub const fn new(queue: &'static Queue) -> Self {
        Self { queue }
    }
}

impl Handler for QueueHandler {
    fn command(&mut self, command: Command, reply: &mut Reply<'_>) {
        match command {
            Command::Help => {
                reply.ok().write_str(HELP).ok();
            }
            Command::Act(action) => {
                if let Err(full) = self.queue.try_submit(action) {
                    write!(reply.err(ErrorCode::Busy), "{full}").ok();
                }
            }
            Command::Status
            | Command::Seed(_)
            | Command::Servo { .. }
            | Command::Save
            | Command::Load
            | Command::Defaults => {
                reply
                    .err(ErrorCode::State)
                    .write_str("not available yet")
                    .ok();
            }
        }
    }
}
