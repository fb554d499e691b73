//! The command queue between whoever asks (the console, a script) and the
//! frame task, which drains it every frame.
//!
//! A ring of `N` slots behind a critical section: any task or interrupt
//! may submit, and [`try_submit`](CommandQueue::try_submit) never waits. A
//! full queue hands the action back ([`QueueFull`]): nothing is dropped
//! silently. The frame task takes at most [`PER_FRAME`] actions a frame, so
//! a flood of commands never delays a frame. The slots are `Cell`s, not a
//! `RefCell` (as in an embassy-sync `Channel`): taking an action has no
//! borrow check and so no panic path on the frame path.

use core::fmt;

use crate::text::{Describe, Text, display_from_describe};

use core::cell::Cell;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

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
    ring: Mutex<CriticalSectionRawMutex, Ring<N>>,
}

/// A queued action and who asked for it.
type Entry = (Action, Option<Asker>);

/// The queue's slots: `len` entries from `head` on, wrapping.
struct Ring<const N: usize> {
    slots: [Cell<Option<Entry>>; N],
    head: Cell<usize>,
    len: Cell<usize>,
}

impl<const N: usize> CommandQueue<N> {
    /// An empty queue (usable in a `static`).
    #[must_use]
    pub const fn new() -> Self {
        const { assert!(N > 0, "a command queue holds at least one action") };
        Self {
            ring: Mutex::new(Ring {
                slots: [const { Cell::new(None) }; N],
                head: Cell::new(0),
                len: Cell::new(0),
            }),
        }
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
        self.ring.lock(|ring| {
            let len = ring.len.get();
            let tail = (ring.head.get() + len) % N;
            match ring.slots.get(tail) {
                Some(slot) if len < N => {
                    slot.set(Some((action, asker)));
                    ring.len.set(len + 1);
                    Ok(())
                }
                _ => Err(QueueFull(action)),
            }
        })
    }

    /// The oldest waiting action, if any.
    pub fn take(&self) -> Option<Action> {
        self.take_asked().map(|(action, _)| action)
    }

    /// The oldest waiting action and who asked for it, if any.
    pub fn take_asked(&self) -> Option<(Action, Option<Asker>)> {
        self.ring.lock(|ring| {
            let len = ring.len.get();
            if len == 0 {
                return None;
            }
            let head = ring.head.get();
            ring.head.set((head + 1) % N);
            ring.len.set(len - 1);
            ring.slots.get(head).and_then(Cell::take)
        })
    }

    /// Actions waiting.
    pub fn len(&self) -> usize {
        self.ring.lock(|ring| ring.len.get())
    }

    /// Whether none is waiting.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
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
    fn first_in_first_out_across_the_wrap() {
        let queue = CommandQueue::<3>::new();
        let asker = |ticket| Some(Asker { port: 1, ticket });
        for round in 0..5_u8 {
            queue
                .try_submit_from(
                    Action::Stop,
                    Asker {
                        port: 1,
                        ticket: round,
                    },
                )
                .unwrap();
            queue.try_submit(Action::Idle(round % 2 == 0)).unwrap();
            assert_eq!(queue.len(), 2);
            assert_eq!(queue.take_asked(), Some((Action::Stop, asker(round))));
            assert_eq!(
                queue.take_asked(),
                Some((Action::Idle(round % 2 == 0), None))
            );
            assert!(queue.is_empty());
            assert_eq!(queue.take_asked(), None);
        }
    }

    #[test]
    fn a_full_queue_hands_the_action_back_and_keeps_the_others() {
        let queue = CommandQueue::<2>::new();
        queue.try_submit(Action::Rest).unwrap();
        queue.try_submit(Action::Stop).unwrap();
        assert_eq!(
            queue.try_submit(Action::Idle(true)),
            Err(QueueFull(Action::Idle(true)))
        );
        assert_eq!(queue.take(), Some(Action::Rest));
        queue.try_submit(Action::Idle(true)).unwrap();
        assert_eq!(queue.take(), Some(Action::Stop));
        assert_eq!(queue.take(), Some(Action::Idle(true)));
        assert_eq!(queue.take(), None);
    }
}
