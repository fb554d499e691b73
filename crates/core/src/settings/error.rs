//! Why settings could not be saved or loaded: one error for the store
//! (with its flash driver's error and its record's validation error) and
//! for the console's `save` and `load` (with neither kept).

use crate::text::{Describe, Text, display_from_describe};

use super::values::SettingsError;

/// The flash, or whatever holds the record, failed: what the console
/// keeps of a flash driver's error.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FlashFailed;

/// Why settings could not be saved or loaded. A store
/// ([`SettingsStore`](super::SettingsStore)) reports its flash driver's
/// error `E` and why its record `I` is invalid; the console's
/// [`SettingsStorage`](super::SettingsStorage) keeps neither
/// ([`FlashFailed`], [`SettingsError`]: the defaults).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StorageError<E = FlashFailed, I = SettingsError> {
    /// Nothing was ever saved (or the range was erased).
    Empty,
    /// The stored bytes are damaged beyond what the store repairs, or do
    /// not decode as the record.
    Corrupt,
    /// A record of an older layout that this firmware cannot migrate.
    Older {
        /// Its version.
        found: u16,
    },
    /// A record saved by firmware with a newer layout.
    Newer {
        /// Its version.
        found: u16,
    },
    /// A record that does not fit the store; or, on a load, a stored one
    /// longer than the buffer that reads it (a firmware with more fields
    /// than this one can read at once), which needs `needs` bytes.
    TooLong {
        /// The buffer the stored record needs, in bytes (a load's).
        needs: Option<usize>,
    },
    /// A record that decodes but fails validation, and why.
    Invalid(I),
    /// The flash driver failed.
    Flash(E),
    /// The board has no settings store.
    Absent,
}

impl<E, I> StorageError<E, I> {
    /// The same error with the flash driver's error dropped, as the
    /// console reports it.
    pub fn forget_flash(self) -> StorageError<FlashFailed, I> {
        match self {
            Self::Empty => StorageError::Empty,
            Self::Corrupt => StorageError::Corrupt,
            Self::Older { found } => StorageError::Older { found },
            Self::Newer { found } => StorageError::Newer { found },
            Self::TooLong { needs } => StorageError::TooLong { needs },
            Self::Invalid(why) => StorageError::Invalid(why),
            Self::Flash(_) => StorageError::Flash(FlashFailed),
            Self::Absent => StorageError::Absent,
        }
    }
}

impl<E, I: Describe> Describe for StorageError<E, I> {
    fn describe(&self, out: &mut dyn Text) {
        match self {
            Self::Empty => out.str("no settings saved"),
            Self::Corrupt => out.str("stored settings are damaged"),
            Self::Older { found } => out
                .str("stored settings are of older version ")
                .u64((*found).into()),
            Self::Newer { found } => out
                .str("stored settings are of newer version ")
                .u64((*found).into()),
            Self::Invalid(e) => out.str("stored settings fail validation: ").with(e),
            Self::TooLong { .. } => out.str("settings do not fit the store"),
            Self::Flash(_) => out.str("the flash failed"),
            Self::Absent => out.str("this board has no settings store"),
        };
    }
}

display_from_describe!(StorageError);
