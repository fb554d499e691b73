//! A bounded first-in first-out queue any task or interrupt may use: `N`
//! slots in a critical-section mutex. The slots are `Cell`s, not a
//! `RefCell` (as in an embassy-sync `Channel`), so neither end has a borrow
//! check, and the frame path, which takes from such queues, no panic path.

use core::cell::Cell;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

/// Up to `N` values of `T`, oldest first; usable in a `static`.
pub struct Ring<T: Copy, const N: usize> {
    slots: Mutex<CriticalSectionRawMutex, Slots<T, N>>,
}

/// `len` values from `head` on, wrapping.
struct Slots<T: Copy, const N: usize> {
    values: [Cell<Option<T>>; N],
    head: Cell<usize>,
    len: Cell<usize>,
}

impl<T: Copy, const N: usize> Ring<T, N> {
    /// An empty queue.
    #[must_use]
    pub const fn new() -> Self {
        const { assert!(N > 0, "a ring holds at least one value") };
        Self {
            slots: Mutex::new(Slots {
                values: [const { Cell::new(None) }; N],
                head: Cell::new(0),
                len: Cell::new(0),
            }),
        }
    }

    /// Appends `value`.
    ///
    /// # Errors
    /// `value` back if `N` values are queued.
    pub fn push(&self, value: T) -> Result<(), T> {
        self.slots.lock(|s| {
            let len = s.len.get();
            match s.values.get((s.head.get() + len) % N) {
                Some(slot) if len < N => {
                    slot.set(Some(value));
                    s.len.set(len + 1);
                    Ok(())
                }
                _ => Err(value),
            }
        })
    }

    /// Takes the oldest value, if any.
    pub fn pop(&self) -> Option<T> {
        self.slots.lock(|s| {
            let len = s.len.get();
            if len == 0 {
                return None;
            }
            let head = s.head.get();
            s.head.set((head + 1) % N);
            s.len.set(len - 1);
            s.values.get(head).and_then(Cell::take)
        })
    }

    /// Values queued.
    pub fn len(&self) -> usize {
        self.slots.lock(|s| s.len.get())
    }

    /// Whether none is queued.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Drops every value.
    pub fn clear(&self) {
        while self.pop().is_some() {}
    }
}

impl<T: Copy, const N: usize> Default for Ring<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::Ring;

    #[test]
    fn first_in_first_out_across_the_wrap() {
        let ring = Ring::<u8, 3>::new();
        for round in 0..5 {
            ring.push(round).unwrap();
            ring.push(round + 100).unwrap();
            assert_eq!(ring.len(), 2);
            assert_eq!(ring.pop(), Some(round));
            assert_eq!(ring.pop(), Some(round + 100));
            assert!(ring.is_empty());
            assert_eq!(ring.pop(), None);
        }
    }

    #[test]
    fn a_full_ring_hands_the_value_back_and_keeps_the_others() {
        let ring = Ring::<u8, 2>::new();
        ring.push(1).unwrap();
        ring.push(2).unwrap();
        assert_eq!(ring.push(3), Err(3));
        assert_eq!(ring.pop(), Some(1));
        ring.push(3).unwrap();
        assert_eq!(ring.pop(), Some(2));
        assert_eq!(ring.pop(), Some(3));
        ring.push(4).unwrap();
        ring.clear();
        assert_eq!(ring.pop(), None);
    }
}
