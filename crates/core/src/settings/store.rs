//! One record in a range of NOR flash, kept by `sequential-storage`.
//!
//! The record is the map's only item (key 0). Its value is the layout
//! version as a little-endian `u16`, then the record's own bytes (see the
//! [module docs](super) for the layout of the settings).

use core::cell::Cell;
use core::marker::PhantomData;
use core::ops::Range;

use crc::{CRC_32_ISO_HDLC, Crc, NoTable};
use embedded_storage_async::nor_flash::NorFlash;
use sequential_storage::Error;
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::map::{MapConfig, MapConfigError, MapStorage, SerializationError, Value};

use super::error::StorageError;
use super::record::{EncodeError, Record, VERSION_LEN, open_record};
use super::report::Loaded;

/// The map key of the record.
const KEY: u8 = 0;
/// Bytes of [`KEY`] as the map stores it.
const KEY_LEN: usize = core::mem::size_of::<u8>();

/// The work buffer a [`SettingsStore`] needs for records of up to
/// `record_len` bytes: the key, the version and the record, in whole
/// 4-byte words.
#[must_use]
pub const fn buffer_len(record_len: usize) -> usize {
    (KEY_LEN + VERSION_LEN + record_len).next_multiple_of(4)
}

/// Why a record was not saved; the stored record is unchanged (or, for a
/// flash failure in the middle of the save, either the old or the new one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SaveError<E> {
    /// The record does not fit the buffer or a flash page.
    TooLong,
    /// The record could not be encoded.
    Encode,
    /// The record did not read back even after erasing the range: the
    /// flash does not keep what is written.
    Corrupt,
    /// The flash driver failed.
    Flash(E),
}

/// A 4-byte aligned buffer: some flash drivers write only from aligned RAM.
#[repr(align(4))]
struct Aligned<const N: usize>([u8; N]);

/// One [`Record`] of type `R` in a range of flash `F`, with a work buffer
/// of `BUF` bytes: at least the encoded record plus 3 (the map's key and
/// the version), rounded up to the flash's word size.
///
/// The range needs at least two erase pages; more pages spread the wear
/// (each save appends about `BUF` bytes at most, a page is erased only
/// when the range is full).
pub struct SettingsStore<F: NorFlash, R, const BUF: usize = 256> {
    map: MapStorage<u8, F, Cache<Uncached, Uncached, Uncached, u8>>,
    buf: Aligned<BUF>,
    _record: PhantomData<fn() -> R>,
}

impl<F: NorFlash, R: Record, const BUF: usize> SettingsStore<F, R, BUF> {
    /// The store in `range` of `flash` (addresses relative to the flash
    /// driver's start, on erase-page boundaries).
    ///
    /// # Errors
    /// A [`MapConfigError`] if the range is not page-aligned or holds fewer
    /// than two pages.
    pub fn new(flash: F, range: Range<u32>) -> Result<Self, MapConfigError> {
        const { assert!(BUF > KEY_LEN + VERSION_LEN, "the work buffer is too small") };
        let config = MapConfig::try_new(range)?;
        Ok(Self {
            map: MapStorage::new(flash, config, Cache::new_uncached()),
            buf: Aligned([0; BUF]),
            _record: PhantomData,
        })
    }

    /// The newest record saved (migrated if it is of an older layout),
    /// with the fields the load skipped or left on their defaults.
    ///
    /// # Errors
    /// A [`StorageError`] saying why there is none to use.
    pub async fn load(&mut self) -> Result<Loaded<R>, StorageError<F::Error, R::Invalid>> {
        match self.map.fetch_item::<&[u8]>(&mut self.buf.0, &KEY).await {
            Ok(Some(stored)) => open_record(stored),
            Ok(None) => Err(StorageError::Empty),
            Err(Error::Storage { value, .. }) => Err(StorageError::Flash(value)),
            Err(Error::BufferTooSmall(needs)) => Err(StorageError::TooLong { needs: Some(needs) }),
            // Damage the map could not repair.
            Err(_) => Err(StorageError::Corrupt),
        }
    }

    /// Saves `record` as the newest, and reads it back.
    ///
    /// A record that does not read back (written over damaged flash) is
    /// written once more, after the damaged spot. If that fails too, or the
    /// store is damaged beyond what `sequential-storage` repairs, or it
    /// holds an item too long for the work buffer (a newer firmware's
    /// record), the range is erased and the record written afresh.
    ///
    /// # Errors
    /// A [`SaveError`]; the stored record is then unchanged, or after a
    /// flash failure halfway, the old or the new one.
    pub async fn save(&mut self, record: &R) -> Result<(), SaveError<F::Error>> {
        let value = Versioned {
            record,
            crc: Cell::new(None),
        };
        for _ in 0..2 {
            match self.map.store_item(&mut self.buf.0, &KEY, &value).await {
                Ok(()) if self.reads_back(&value).await? => return Ok(()),
                Ok(()) => {}
                Err(Error::Corrupted { .. } | Error::BufferTooSmall(_)) => break,
                Err(e) => return Err(save_error(e)),
            }
        }
        self.map.erase_all().await.map_err(save_error)?;
        self.map
            .store_item(&mut self.buf.0, &KEY, &value)
            .await
            .map_err(save_error)?;
        if self.reads_back(&value).await? {
            Ok(())
        } else {
            Err(SaveError::Corrupt)
        }
    }

    /// Whether a load now gives the bytes `value` was written as.
    async fn reads_back(&mut self, value: &Versioned<'_, R>) -> Result<bool, SaveError<F::Error>> {
        match self.map.fetch_item::<&[u8]>(&mut self.buf.0, &KEY).await {
            Ok(Some(bytes)) => Ok(value.crc.get() == Some(CRC32.checksum(bytes))),
            Ok(None) | Err(Error::Corrupted { .. } | Error::BufferTooSmall(_)) => Ok(false),
            Err(e) => Err(save_error(e)),
        }
    }

    /// Erases the whole range: the next load finds nothing.
    ///
    /// # Errors
    /// The flash driver's error.
    pub async fn erase(&mut self) -> Result<(), SaveError<F::Error>> {
        self.map.erase_all().await.map_err(save_error)
    }

    /// The flash driver.
    pub fn flash(&mut self) -> &mut F {
        self.map.flash()
    }

    /// Gives the flash driver back.
    pub fn into_flash(self) -> F {
        self.map.destroy().0
    }
}

/// A record with its version in front, as the map stores it, and the
/// CRC of the bytes it was written as (to read them back against). The
/// store reads records as `&[u8]` and checks the version itself, so this
/// type is only ever written.
struct Versioned<'r, R> {
    record: &'r R,
    crc: Cell<Option<u32>>,
}

/// The read-back check (bitwise: no table in flash).
const CRC32: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISO_HDLC);

impl<'a, R: Record> Value<'a> for Versioned<'_, R> {
    fn serialize_into(&self, buffer: &mut [u8]) -> Result<usize, SerializationError> {
        let (version, payload) = buffer
            .split_first_chunk_mut::<VERSION_LEN>()
            .ok_or(SerializationError::BufferTooSmall)?;
        *version = R::VERSION.to_le_bytes();
        let len = match self.record.encode(payload) {
            Ok(used) => VERSION_LEN.saturating_add(used),
            Err(EncodeError::TooLong) => return Err(SerializationError::BufferTooSmall),
            Err(EncodeError::Unsupported) => return Err(SerializationError::InvalidData),
        };
        let written = buffer
            .get(..len)
            .ok_or(SerializationError::BufferTooSmall)?;
        self.crc.set(Some(CRC32.checksum(written)));
        Ok(len)
    }

    fn deserialize_from(_: &'a [u8]) -> Result<(Self, usize), SerializationError> {
        // Never called: loading goes through `&[u8]`.
        Err(SerializationError::InvalidFormat)
    }
}

fn save_error<E>(error: Error<E>) -> SaveError<E> {
    match error {
        Error::Storage { value, .. } => SaveError::Flash(value),
        Error::FullStorage
        | Error::ItemTooBig
        | Error::BufferTooSmall(_)
        | Error::SerializationError(SerializationError::BufferTooSmall) => SaveError::TooLong,
        Error::SerializationError(_) => SaveError::Encode,
        _ => SaveError::Corrupt,
    }
}
