//! What a load did besides reading values: the fields it skipped or left
//! on their defaults ([`FieldReport`]), and the layout version it read
//! ([`Loaded`]).

use core::fmt;

/// A set of field ids (`u8`): which fields a load skipped or defaulted.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct FieldSet([u32; 8]);

impl FieldSet {
    /// No field.
    pub const EMPTY: Self = Self([0; 8]);

    /// The set of `ids`.
    #[must_use]
    pub const fn of(ids: &[u8]) -> Self {
        let mut set = Self::EMPTY;
        let mut i = 0;
        while i < ids.len() {
            set = set.with(ids[i]);
            i += 1;
        }
        set
    }

    /// This set and `id`.
    #[must_use]
    pub const fn with(mut self, id: u8) -> Self {
        self.0[(id / 32) as usize] |= 1 << (id % 32);
        self
    }

    /// The ids in this set or in `other`.
    #[must_use]
    pub const fn union(mut self, other: &Self) -> Self {
        let mut i = 0;
        while i < self.0.len() {
            self.0[i] |= other.0[i];
            i += 1;
        }
        self
    }

    /// Adds `id`; `false` if it was in the set already.
    pub const fn insert(&mut self, id: u8) -> bool {
        let had = self.contains(id);
        *self = self.with(id);
        !had
    }

    /// Whether `id` is in the set.
    #[must_use]
    pub const fn contains(&self, id: u8) -> bool {
        self.0[(id / 32) as usize] & (1 << (id % 32)) != 0
    }

    /// The ids of this set that are not in `other`.
    #[must_use]
    pub const fn without(mut self, other: &Self) -> Self {
        let mut i = 0;
        while i < self.0.len() {
            self.0[i] &= !other.0[i];
            i += 1;
        }
        self
    }

    /// Whether the set is empty.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        let mut i = 0;
        while i < self.0.len() {
            if self.0[i] != 0 {
                return false;
            }
            i += 1;
        }
        true
    }

    /// How many ids the set holds.
    #[must_use]
    pub fn len(&self) -> usize {
        self.0.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// The ids, smallest first.
    pub fn iter(&self) -> impl Iterator<Item = u8> + '_ {
        (0..=u8::MAX).filter(|&id| self.contains(id))
    }
}

impl fmt::Debug for FieldSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_set().entries(self.iter()).finish()
    }
}

/// The ids, space-separated (`3 17 57`), for the boot log.
#[cfg(feature = "defmt")]
impl defmt::Format for FieldSet {
    fn format(&self, f: defmt::Formatter<'_>) {
        for (i, id) in self.iter().enumerate() {
            let gap = if i == 0 { "" } else { " " };
            defmt::write!(f, "{=str}{=u8}", gap, id);
        }
    }
}

/// The fields a load did not take from the record as they were stored;
/// every other field of the record kept its stored value.
///
/// None of them stops a load: the record is used, and the boot log names
/// the fields (see the [module docs](super) for the rules).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FieldReport {
    /// Fields this firmware does not know (saved by a newer firmware):
    /// skipped. A `save` by this firmware leaves them out.
    pub unknown: FieldSet,
    /// Fields this firmware has that the record lacks (saved by an older
    /// firmware): on their defaults. Expected after an update.
    pub missing: FieldSet,
    /// Fields whose stored bytes are not a value of their type (a wrong
    /// length, a percentage over 100, an unknown tag): on their defaults.
    pub rejected: FieldSet,
}

impl FieldReport {
    /// Whether every field was read as stored and none is missing.
    #[must_use]
    pub const fn is_clean(&self) -> bool {
        self.unknown.is_empty() && self.missing.is_empty() && self.rejected.is_empty()
    }
}

/// A record as loaded, with what the load did to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Loaded<R> {
    /// The record.
    pub record: R,
    /// The layout version it was stored with: an older one than the
    /// record's [`VERSION`](super::Record::VERSION) has been migrated.
    pub version: u16,
    /// Fields skipped or left on their defaults.
    pub fields: FieldReport,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_holds_every_u8() {
        let mut set = FieldSet::EMPTY;
        assert!(set.is_empty());
        for id in [0, 1, 31, 32, 57, 200, 255] {
            assert!(!set.contains(id));
            assert!(set.insert(id));
            assert!(!set.insert(id), "{id} twice");
        }
        assert_eq!(set.len(), 7);
        assert_eq!(set.iter().collect::<Vec<_>>(), [0, 1, 31, 32, 57, 200, 255]);
        assert_eq!(format!("{set:?}"), "{0, 1, 31, 32, 57, 200, 255}");
        let rest = set.without(&FieldSet::of(&[1, 57, 255, 3]));
        assert_eq!(rest.iter().collect::<Vec<_>>(), [0, 31, 32, 200]);
        assert_eq!(FieldSet::of(&[9, 9]).len(), 1);
        assert!(FieldReport::default().is_clean());
        let report = FieldReport {
            missing: FieldSet::of(&[4]),
            ..FieldReport::default()
        };
        assert!(!report.is_clean());
    }
}
