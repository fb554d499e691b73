//! The record trait: a settings type, its bytes and its layout version.

/// A settings record as stored in flash.
///
/// The store writes [`VERSION`](Self::VERSION) next to the bytes of
/// [`encode`](Self::encode) and checks it before calling
/// [`decode`](Self::decode), so `decode` only ever sees bytes written for
/// its own version. Change the version whenever the encoding changes (a
/// field added, removed, reordered or retyped): a record of another
/// version loads as [`LoadError::Older`](super::LoadError::Older) or
/// [`LoadError::Newer`](super::LoadError::Newer), and the firmware falls
/// back to its defaults.
pub trait Record: Sized {
    /// The version of the layout [`encode`](Self::encode) writes.
    const VERSION: u16;

    /// Writes the record into `buf`, returning the length used.
    ///
    /// # Errors
    /// [`EncodeError::TooLong`] if `buf` is too small.
    fn encode(&self, buf: &mut [u8]) -> Result<usize, EncodeError>;

    /// Reads a record written by [`encode`](Self::encode) (with the same
    /// version).
    ///
    /// # Errors
    /// [`DecodeError::Malformed`] for bytes that are not an encoding,
    /// [`DecodeError::Invalid`] for a record that fails validation.
    fn decode(bytes: &[u8]) -> Result<Self, DecodeError>;
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

/// Why bytes are not a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// Not an encoding of the record (truncated, bytes left over, a value
    /// its type cannot hold).
    Malformed,
    /// A well-formed record that fails validation.
    Invalid,
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

    fn encode(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        let out = buf.get_mut(..self.0.len()).ok_or(EncodeError::TooLong)?;
        out.copy_from_slice(&self.0);
        Ok(self.0.len())
    }

    fn decode(bytes: &[u8]) -> Result<Self, DecodeError> {
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
pub fn decode_postcard<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> Result<T, DecodeError> {
    match postcard::take_from_bytes(bytes) {
        Ok((value, [])) => Ok(value),
        _ => Err(DecodeError::Malformed),
    }
}
