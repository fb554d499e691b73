//! A value shared between tasks and interrupts ([`SharedCell`]): what the
//! links between the console, the frame task, the receivers and the input
//! task are made of.

use core::cell::Cell;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

/// A copy of a `T` behind a critical section: each access copies it in or
/// out (or changes it in place) with the interrupts masked, and no borrow
/// can fail, so nothing here puts a panic path on the frame path and no
/// reader waits for a writer beyond the copy.
pub struct SharedCell<T>(Mutex<CriticalSectionRawMutex, Cell<T>>);

impl<T: Copy> SharedCell<T> {
    /// Holding `value`.
    #[must_use]
    pub const fn new(value: T) -> Self {
        Self(Mutex::new(Cell::new(value)))
    }

    /// The value.
    pub fn get(&self) -> T {
        self.0.lock(Cell::get)
    }

    /// Replaces the value.
    pub fn set(&self, value: T) {
        self.0.lock(|cell| cell.set(value));
    }

    /// Replaces the value, returning the one it held.
    pub fn replace(&self, value: T) -> T {
        self.0.lock(|cell| cell.replace(value))
    }

    /// Changes the value with `f` in one critical section (no other
    /// access in between), returning what `f` returns.
    pub fn update<R>(&self, f: impl FnOnce(&mut T) -> R) -> R {
        self.0.lock(|cell| {
            let mut value = cell.get();
            let result = f(&mut value);
            cell.set(value);
            result
        })
    }
}

impl<T: Copy + Default> Default for SharedCell<T> {
    fn default() -> Self {
        Self::new(T::default())
    }
}

impl<T: Copy + core::fmt::Debug> core::fmt::Debug for SharedCell<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_tuple("SharedCell").field(&self.get()).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::SharedCell;

    #[test]
    fn a_value_in_and_out() {
        let shared = SharedCell::new(3_u32);
        assert_eq!(shared.get(), 3);
        shared.set(5);
        assert_eq!(shared.replace(7), 5);
        assert_eq!(shared.update(|v| core::mem::replace(v, *v * 2)), 7);
        assert_eq!(shared.get(), 14);
    }
}
