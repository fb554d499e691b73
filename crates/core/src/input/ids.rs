//! Which inputs a board has: their numbers, as the console names them
//! ([`InputIds`]). The board chooses them (the RP boards: each input's
//! GPIO number); the core only keeps a role for each, in the settings'
//! [`SLOTS`].

use crate::text::{Describe, Text, display_from_describe};

use super::SLOTS;

/// A board's trigger inputs: how many (0 to [`SLOTS`]) and each one's
/// number, distinct. The input in slot `i` (bit `i` of the levels, role `i`
/// of the settings) is the one numbered `ids[i]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InputIds {
    ids: [u8; SLOTS],
    len: u8,
}

/// Why a list of input numbers cannot be a board's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum IdsError {
    /// More inputs than the settings keep roles for ([`SLOTS`]).
    TooMany {
        /// How many were given.
        given: usize,
    },
    /// The same number twice.
    Repeated {
        /// The number.
        id: u8,
    },
}

impl InputIds {
    /// No inputs: every `input <n>` is refused, and the input task never
    /// runs.
    pub const NONE: Self = Self {
        ids: [0; SLOTS],
        len: 0,
    };

    /// The inputs numbered `ids`, slot 0 first.
    ///
    /// # Errors
    /// [`IdsError`] if there are more than [`SLOTS`] or a number repeats.
    pub const fn new(ids: &[u8]) -> Result<Self, IdsError> {
        if ids.len() > SLOTS {
            return Err(IdsError::TooMany { given: ids.len() });
        }
        let mut out = [0; SLOTS];
        let mut i = 0;
        while i < ids.len() {
            let mut j = 0;
            while j < i {
                if ids[j] == ids[i] {
                    return Err(IdsError::Repeated { id: ids[i] });
                }
                j += 1;
            }
            out[i] = ids[i];
            i += 1;
        }
        Ok(Self {
            ids: out,
            len: ids.len() as u8,
        })
    }

    /// The numbers, slot 0 first.
    #[must_use]
    pub fn as_slice(&self) -> &[u8] {
        self.ids.get(..usize::from(self.len)).unwrap_or_default()
    }

    /// How many inputs.
    #[must_use]
    pub const fn len(&self) -> usize {
        self.len as usize
    }

    /// Whether the board has none.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The slot of the input numbered `id`, if the board has it.
    #[must_use]
    pub fn slot(&self, id: u8) -> Option<usize> {
        self.as_slice().iter().position(|&n| n == id)
    }

    /// The number of the input in `slot`, if there is one.
    #[must_use]
    pub fn id(&self, slot: usize) -> Option<u8> {
        self.as_slice().get(slot).copied()
    }
}

impl Default for InputIds {
    fn default() -> Self {
        Self::NONE
    }
}

/// The numbers as a reply lists them: `2, 3, 4, 5`, or `none`.
impl Describe for InputIds {
    fn describe(&self, out: &mut dyn Text) {
        if self.is_empty() {
            out.str("none");
        }
        for (i, &id) in self.as_slice().iter().enumerate() {
            if i > 0 {
                out.str(", ");
            }
            out.u64(id.into());
        }
    }
}

display_from_describe!(InputIds);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_follow_the_order_given() {
        let ids = InputIds::new(&[7, 2, 30]).unwrap();
        assert_eq!(ids.len(), 3);
        assert_eq!(ids.slot(2), Some(1));
        assert_eq!(ids.slot(30), Some(2));
        assert_eq!(ids.slot(3), None);
        assert_eq!(ids.id(0), Some(7));
        assert_eq!(ids.id(3), None);
        assert_eq!(ids.to_string(), "7, 2, 30");
    }

    #[test]
    fn too_many_or_repeated_numbers_are_refused() {
        assert_eq!(
            InputIds::new(&[1, 2, 3, 4, 5]),
            Err(IdsError::TooMany { given: 5 })
        );
        assert_eq!(InputIds::new(&[4, 5, 4]), Err(IdsError::Repeated { id: 4 }));
    }

    #[test]
    fn no_inputs() {
        let ids = InputIds::new(&[]).unwrap();
        assert_eq!(ids, InputIds::NONE);
        assert!(ids.is_empty());
        assert_eq!(ids.slot(0), None);
        assert_eq!(ids.to_string(), "none");
    }
}
