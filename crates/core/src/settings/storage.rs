//! Where the console's `save` and `load` go: a small trait each board
//! implements ([`SettingsStorage`]), and [`RamStorage`], a record kept in
//! RAM (the QEMU image's store; tests).

use crate::text::{Describe, Text, display_from_describe};

use super::record::{Record, VERSION_LEN, open_record};
use super::report::LoadError;
use super::store::SaveError;
use super::values::{Settings, SettingsError};
use super::{SETTINGS_BUFFER, SETTINGS_LEN};

/// Why `save` or `load` failed: the board-neutral form of the store's
/// errors, for the console's `err storage` reply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StorageError {
    /// Nothing saved yet.
    Empty,
    /// The stored bytes are damaged or not a record.
    Corrupt,
    /// A record of an older layout version that cannot be migrated.
    Older {
        /// Its version.
        found: u16,
    },
    /// A record of a newer layout version.
    Newer {
        /// Its version.
        found: u16,
    },
    /// A record that fails validation, and why.
    Invalid(SettingsError),
    /// The record does not fit the store (or a stored one does not fit the
    /// buffer that reads it).
    TooLong,
    /// The flash (or whatever holds the record) failed.
    Device,
}

impl Describe for StorageError {
    fn describe(&self, out: &mut dyn Text) {
        match *self {
            Self::Empty => out.str("no settings saved"),
            Self::Corrupt => out.str("stored settings are damaged"),
            Self::Older { found } => out
                .str("stored settings are of older version ")
                .u64(found.into()),
            Self::Newer { found } => out
                .str("stored settings are of newer version ")
                .u64(found.into()),
            Self::Invalid(e) => out.str("stored settings fail validation: ").with(&e),
            Self::TooLong => out.str("settings do not fit the store"),
            Self::Device => out.str("the flash failed"),
        };
    }
}

display_from_describe!(StorageError);

impl<E> From<LoadError<E, SettingsError>> for StorageError {
    fn from(e: LoadError<E, SettingsError>) -> Self {
        match e {
            LoadError::Empty => Self::Empty,
            LoadError::Corrupt => Self::Corrupt,
            LoadError::Older { found } => Self::Older { found },
            LoadError::Newer { found } => Self::Newer { found },
            LoadError::TooLong { .. } => Self::TooLong,
            LoadError::Invalid(e) => Self::Invalid(e),
            LoadError::Flash(_) => Self::Device,
        }
    }
}

impl<E> From<SaveError<E>> for StorageError {
    fn from(e: SaveError<E>) -> Self {
        match e {
            SaveError::TooLong | SaveError::Encode => Self::TooLong,
            SaveError::Corrupt => Self::Corrupt,
            SaveError::Flash(_) => Self::Device,
        }
    }
}

/// The board's settings store, as the console service uses it.
///
/// Called from the console task only (never from the frame path), once
/// per `save` or `load` command; a call may block for as long as a flash
/// write takes (the frame task runs at a higher priority meanwhile). On
/// the Pico it wraps a [`SettingsStore`](super::SettingsStore) over the
/// flash driver (e.g. with `embassy_futures::block_on`).
pub trait SettingsStorage {
    /// Stores `settings` (a power cut leaves the old or the new ones).
    ///
    /// # Errors
    /// Why nothing new was stored.
    fn save(&mut self, settings: &Settings) -> Result<(), StorageError>;

    /// The settings stored last (migrated from an older layout if need
    /// be; fields the record lacks on their defaults).
    ///
    /// # Errors
    /// Why none could be loaded (the caller keeps its settings).
    fn load(&mut self) -> Result<Settings, StorageError>;
}

/// A storage borrowed for good: a board keeps its store (and the record
/// buffer in it) in a static, and hands the console service a reference.
impl<T: SettingsStorage + ?Sized> SettingsStorage for &mut T {
    fn save(&mut self, settings: &Settings) -> Result<(), StorageError> {
        (**self).save(settings)
    }

    fn load(&mut self) -> Result<Settings, StorageError> {
        (**self).load()
    }
}

/// One record kept in RAM as the flash store keeps it (version, then the
/// record's bytes), `N` bytes at most (by default as many as the flash
/// store's buffer holds): lost at reset.
#[derive(Clone, Debug)]
pub struct RamStorage<const N: usize = SETTINGS_BUFFER> {
    bytes: [u8; N],
    /// Bytes used (0: nothing saved).
    len: usize,
}

impl<const N: usize> RamStorage<N> {
    /// An empty store.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            bytes: [0; N],
            len: 0,
        }
    }

    /// The stored bytes: the version (little-endian `u16`), then the record.
    #[must_use]
    pub fn raw(&self) -> &[u8] {
        self.bytes.get(..self.len).unwrap_or_default()
    }

    /// Replaces the stored bytes (a test's damaged or old record).
    ///
    /// # Errors
    /// [`StorageError::TooLong`] if they do not fit.
    pub fn set_raw(&mut self, raw: &[u8]) -> Result<(), StorageError> {
        let slot = self
            .bytes
            .get_mut(..raw.len())
            .ok_or(StorageError::TooLong)?;
        slot.copy_from_slice(raw);
        self.len = raw.len();
        Ok(())
    }
}

impl<const N: usize> Default for RamStorage<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> SettingsStorage for RamStorage<N> {
    /// Refuses with [`StorageError::TooLong`], keeping the stored record,
    /// if `N` is less than a record's longest ([`SETTINGS_LEN`] and the
    /// version).
    fn save(&mut self, settings: &Settings) -> Result<(), StorageError> {
        if N < VERSION_LEN + SETTINGS_LEN {
            return Err(StorageError::TooLong);
        }
        let (version, body) = self
            .bytes
            .split_at_mut_checked(VERSION_LEN)
            .ok_or(StorageError::TooLong)?;
        let used = settings.encode(body).map_err(|_| StorageError::TooLong)?;
        version.copy_from_slice(&Settings::VERSION.to_le_bytes());
        self.len = VERSION_LEN + used;
        Ok(())
    }

    fn load(&mut self) -> Result<Settings, StorageError> {
        match self.raw() {
            [] => Err(StorageError::Empty),
            stored => open_record::<Settings, ()>(stored)
                .map(|loaded| loaded.record)
                .map_err(StorageError::from),
        }
    }
}
