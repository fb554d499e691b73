//! Where the console's `save` and `load` go: a small trait each board
//! implements ([`SettingsStorage`]), and [`RamStorage`], a record kept in
//! RAM (the QEMU image's store; tests).

use super::error::{FlashFailed, StorageError};
use super::record::{Record, VERSION_LEN, open_record};
use super::store::SaveError;
use super::values::Settings;
use super::{SETTINGS_BUFFER, SETTINGS_LEN};

impl<E> From<SaveError<E>> for StorageError {
    fn from(e: SaveError<E>) -> Self {
        match e {
            SaveError::TooLong | SaveError::Encode => Self::TooLong { needs: None },
            SaveError::Corrupt => Self::Corrupt,
            SaveError::Flash(_) => Self::Flash(FlashFailed),
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

/// A board's store, if it has one: `None` refuses every `save` and `load`
/// with [`StorageError::Absent`] (the console's `err unavailable`).
impl<T: SettingsStorage> SettingsStorage for Option<T> {
    fn save(&mut self, settings: &Settings) -> Result<(), StorageError> {
        self.as_mut().ok_or(StorageError::Absent)?.save(settings)
    }

    fn load(&mut self) -> Result<Settings, StorageError> {
        self.as_mut().ok_or(StorageError::Absent)?.load()
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
            .ok_or(StorageError::TooLong { needs: None })?;
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
            return Err(StorageError::TooLong { needs: None });
        }
        let (version, body) = self
            .bytes
            .split_at_mut_checked(VERSION_LEN)
            .ok_or(StorageError::TooLong { needs: None })?;
        let used = settings
            .encode(body)
            .map_err(|_| StorageError::TooLong { needs: None })?;
        version.copy_from_slice(&Settings::VERSION.to_le_bytes());
        self.len = VERSION_LEN + used;
        Ok(())
    }

    fn load(&mut self) -> Result<Settings, StorageError> {
        match self.raw() {
            [] => Err(StorageError::Empty),
            stored => open_record::<Settings, ()>(stored)
                .map(|loaded| loaded.record)
                .map_err(StorageError::forget_flash),
        }
    }
}
