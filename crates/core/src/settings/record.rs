//! The record trait: a settings type, its bytes and its layout version.

use super::error::StorageError;
use super::report::{FieldReport, Loaded};

/// Bytes of the version in front of a stored record.
pub(super) const VERSION_LEN: usize = 2;

/// A settings record as stored: its bytes and the version of their layout.
///
/// The store writes [`VERSION`](Self::VERSION) next to the bytes of
/// [`encode`](Self::encode), and hands both to [`decode`](Self::decode) on
/// a load. A record of a newer version than `VERSION` is refused before
/// `decode` sees it ([`StorageError::Newer`](super::StorageError::Newer)); an
/// older one is `decode`'s to migrate, or to refuse with
/// [`DecodeError::Version`] ([`StorageError::Older`](super::StorageError::Older)).
/// The [`Settings`](super::Settings) record is a list of tagged fields
/// whose layout does not change when a field is added (see the [module
/// docs](super)).
pub trait Record: Sized {
    /// The version of the layout [`encode`](Self::encode) writes.
    const VERSION: u16;

    /// Why a record that reads well is refused (`()` if it never is).
    type Invalid;

    /// Writes the record into `buf`, returning the length used.
    ///
    /// # Errors
    /// [`EncodeError::TooLong`] if `buf` is too small.
    fn encode(&self, buf: &mut [u8]) -> Result<usize, EncodeError>;

    /// Reads a record stored with layout `version` (at most
    /// [`VERSION`](Self::VERSION)), and notes in `fields` what it skipped
    /// or left on its defaults.
    ///
    /// # Errors
    /// [`DecodeError::Malformed`] for bytes that are not a record of that
    /// version, [`DecodeError::Version`] for a version it cannot read,
    /// [`DecodeError::Invalid`] for a record that fails validation.
    fn decode(
        version: u16,
        bytes: &[u8],
        fields: &mut FieldReport,
    ) -> Result<Self, DecodeError<Self::Invalid>>;
}

/// Why a record could not be written into a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// The buffer is too small.
    TooLong,
    /// The encoder refused the value.
    Unsupported,
}

/// Why bytes are not a record; `I` says why a record is invalid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError<I> {
    /// Not an encoding of the record (truncated, bytes left over, a field
    /// twice).
    Malformed,
    /// A layout version this record cannot read.
    Version,
    /// A well-formed record that fails validation, and why.
    Invalid(I),
}

/// The record stored as `stored` (the version, little-endian, then the
/// record's bytes), as the flash store and [`RamStorage`] keep it.
///
/// [`RamStorage`]: super::RamStorage
///
/// # Errors
/// A [`StorageError`] saying why it cannot be used (never `Empty`, `TooLong`
/// or `Flash`).
pub(super) fn open_record<R: Record, E>(
    stored: &[u8],
) -> Result<Loaded<R>, StorageError<E, R::Invalid>> {
    let Some((version, bytes)) = stored.split_first_chunk::<VERSION_LEN>() else {
        return Err(StorageError::Corrupt);
    };
    let version = u16::from_le_bytes(*version);
    if version > R::VERSION {
        return Err(StorageError::Newer { found: version });
    }
    let mut fields = FieldReport::default();
    match R::decode(version, bytes, &mut fields) {
        Ok(record) => Ok(Loaded {
            record,
            version,
            fields,
        }),
        Err(DecodeError::Malformed) => Err(StorageError::Corrupt),
        Err(DecodeError::Version) => Err(StorageError::Older { found: version }),
        Err(DecodeError::Invalid(why)) => Err(StorageError::Invalid(why)),
    }
}

/// A record of layout version `V` kept as its bytes, at most `N`: for tools
/// that plant a store of another version (tests, the emulator's runs) or
/// read a record's bytes as they are.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RawRecord<const V: u16, const N: usize>(pub heapless::Vec<u8, N>);

impl<const V: u16, const N: usize> RawRecord<V, N> {
    /// `bytes` as a record; `None` if they are more than `N`.
    #[must_use]
    pub fn new(bytes: &[u8]) -> Option<Self> {
        heapless::Vec::from_slice(bytes).ok().map(Self)
    }
}

impl<const V: u16, const N: usize> Record for RawRecord<V, N> {
    const VERSION: u16 = V;
    type Invalid = ();

    fn encode(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        let out = buf.get_mut(..self.0.len()).ok_or(EncodeError::TooLong)?;
        out.copy_from_slice(&self.0);
        Ok(self.0.len())
    }

    /// The bytes of a record of version `V`, as they are.
    fn decode(version: u16, bytes: &[u8], _: &mut FieldReport) -> Result<Self, DecodeError<()>> {
        if version != V {
            return Err(DecodeError::Version);
        }
        Self::new(bytes).ok_or(DecodeError::Malformed)
    }
}

/// [`Record::encode`] for a serde type, with postcard (compact: integers
/// as varints, no field names).
///
/// # Errors
/// [`EncodeError::TooLong`] if `buf` is too small.
#[cfg(feature = "postcard")]
pub fn encode_postcard<T: serde::Serialize>(
    value: &T,
    buf: &mut [u8],
) -> Result<usize, EncodeError> {
    match postcard::to_slice(value, buf) {
        Ok(used) => Ok(used.len()),
        Err(postcard::Error::SerializeBufferFull) => Err(EncodeError::TooLong),
        Err(_) => Err(EncodeError::Unsupported),
    }
}

/// [`Record::decode`] for a serde type, with postcard; every byte must
/// belong to the value.
///
/// # Errors
/// [`DecodeError::Malformed`] if the bytes are not exactly one value.
#[cfg(feature = "postcard")]
pub fn decode_postcard<T: serde::de::DeserializeOwned, I>(
    bytes: &[u8],
) -> Result<T, DecodeError<I>> {
    match postcard::take_from_bytes(bytes) {
        Ok((value, [])) => Ok(value),
        _ => Err(DecodeError::Malformed),
    }
}
