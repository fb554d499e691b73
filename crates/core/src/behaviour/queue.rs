//! The command queue between whoever asks (the console, a script) and the
//! frame task, which drains it every frame.
//!
//! A [`Ring`]: any task or interrupt may submit, and
//! [`try_submit`](CommandQueue::try_submit) never waits. A full queue hands
//! the action back ([`QueueFull`]): nothing is dropped silently. The frame
//! task takes at most [`PER_FRAME`] actions a frame, so a flood of commands
//! never delays a frame.

use core::fmt;

use crate::text::{Describe, Text, display_from_describe};

use crate::ring::Ring;

use crate::command::Action;

/// Actions the frame task applies per frame at most.
pub const PER_FRAME: usize = 2;

/// The queue's capacity on the boards.
pub const CAPACITY: usize = 8;

/// Who asked for a queued action and is waiting for its outcome: a
/// console port and the ticket the port's console gave it (see
/// [`ConsoleLink::answer`](crate::console::ConsoleLink::answer)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Asker {
    /// The port (`0..console::PORTS`).
    pub port: u8,
    /// The ticket, to tell this action's outcome from an older one's.
    pub ticket: u8,
}

/// The queue was full: the action was not taken (here it is back).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QueueFull(pub Action);

impl Describe for QueueFull {
    fn describe(&self, out: &mut dyn Text) {
        out.str("command queue full: try again after the next frame");
    }
}

display_from_describe!(QueueFull);

impl core::error::Error for QueueFull {}

/// Actions waiting for the frame task, at most `N`.
///
/// ```
/// use idle_head_core::behaviour::{CommandQueue, QueueFull};
/// use idle_head_core::command::Action;
///
/// static QUEUE: CommandQueue<2> = CommandQueue::new();
/// QUEUE.try_submit(Action::Stop).unwrap();
/// QUEUE.try_submit(Action::Idle(true)).unwrap();
/// assert_eq!(QUEUE.try_submit(Action::Idle(false)), Err(QueueFull(Action::Idle(false))));
/// assert_eq!(QUEUE.take(), Some(Action::Stop));
/// ```
pub struct CommandQueue<const N: usize = CAPACITY> {
    ring: Ring<(Action, Option<Asker>), N>,
}

impl<const N: usize> CommandQueue<N> {
    /// An empty queue (usable in a `static`).
    #[must_use]
    pub const fn new() -> Self {
        Self { ring: Ring::new() }
    }

    /// Queues `action` for the frame task.
    ///
    /// # Errors
    /// [`QueueFull`] with the action if `N` actions are waiting.
    pub fn try_submit(&self, action: Action) -> Result<(), QueueFull> {
        self.submit(action, None)
    }

    /// Queues `action` for the frame task, which tells `asker` its outcome.
    ///
    /// # Errors
    /// [`QueueFull`] with the action if `N` actions are waiting.
    pub fn try_submit_from(&self, action: Action, asker: Asker) -> Result<(), QueueFull> {
        self.submit(action, Some(asker))
    }

    fn submit(&self, action: Action, asker: Option<Asker>) -> Result<(), QueueFull> {
        self.ring
            .push((action, asker))
            .map_err(|(action, _)| QueueFull(action))
    }

    /// The oldest waiting action, if any.
    pub fn take(&self) -> Option<Action> {
        self.take_asked().map(|(action, _)| action)
    }

    /// The oldest waiting action and who asked for it, if any.
    pub fn take_asked(&self) -> Option<(Action, Option<Asker>)> {
        self.ring.pop()
    }

    /// Actions waiting.
    pub fn len(&self) -> usize {
        self.ring.len()
    }

    /// Whether none is waiting.
    pub fn is_empty(&self) -> bool {
        self.ring.is_empty()
    }
}

impl<const N: usize> Default for CommandQueue<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> fmt::Debug for CommandQueue<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CommandQueue")
            .field("waiting", &self.len())
            .field("capacity", &N)
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_asker_comes_back_with_its_action_and_a_full_queue_hands_it_back() {
        let queue = CommandQueue::<2>::new();
        let asker = Asker { port: 1, ticket: 7 };
        queue.try_submit_from(Action::Rest, asker).unwrap();
        queue.try_submit(Action::Stop).unwrap();
        assert_eq!(
            queue.try_submit(Action::Idle(true)),
            Err(QueueFull(Action::Idle(true)))
        );
        assert_eq!(queue.take_asked(), Some((Action::Rest, Some(asker))));
        assert_eq!(queue.take_asked(), Some((Action::Stop, None)));
        assert_eq!(queue.take(), None);
    }
}
