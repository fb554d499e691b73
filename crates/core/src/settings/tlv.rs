//! Tagged fields: the record as a list of `id, length, value` entries
//! ([`Writer`], [`Entries`]), and how each type of value is written
//! ([`FieldValue`]). The ids and where each value lives are in
//! [`fields`](super::fields).

use crate::behaviour::MilliHertz;
use crate::command::{Hold, Percent};
use crate::dmx::DmxAddress;
use crate::driver::{DegreesPerSecond, DegreesPerSecondSquared};
use crate::servo::{Direction, NanosPerDegree, ServoRate};
use crate::units::{Angle, Microseconds, Millis};

use super::record::EncodeError;

/// Bytes in front of each value: its id and its length.
pub(super) const HEADER: usize = 2;

/// A type a field can hold: its bytes in the record.
///
/// An encoding never changes once a field of the type has been saved:
/// firmware of every age reads it (a field that needs another encoding
/// gets a new id).
pub(super) trait FieldValue: Sized {
    /// Most bytes a value takes, at most 255 (the length is one byte).
    const MAX_LEN: usize;

    /// Writes the value into `out` (at least [`MAX_LEN`](Self::MAX_LEN)
    /// bytes) and returns how many bytes it took.
    fn to_bytes(&self, out: &mut [u8]) -> usize;

    /// The value `bytes` hold (exactly a field's bytes); `None` if they are
    /// not one: a wrong length, a value the type cannot hold.
    fn from_bytes(bytes: &[u8]) -> Option<Self>;
}

/// The entries of a record, written one after the other into a buffer.
pub(super) struct Writer<'a> {
    buf: &'a mut [u8],
    len: usize,
    /// An entry did not fit.
    full: bool,
}

impl<'a> Writer<'a> {
    pub(super) const fn new(buf: &'a mut [u8]) -> Self {
        Self {
            buf,
            len: 0,
            full: false,
        }
    }

    /// Writes field `id` holding `value`.
    pub(super) fn field<T: FieldValue>(&mut self, id: u8, value: &T) {
        const {
            assert!(
                T::MAX_LEN <= u8::MAX as usize,
                "a field's length is one byte"
            );
        }
        if self.full {
            return;
        }
        match self.value_slot(T::MAX_LEN) {
            Some(slot) => {
                let used = value.to_bytes(slot);
                self.commit(id, used);
            }
            None => self.full = true,
        }
    }

    /// Room for a value of up to `max` bytes after the next header.
    #[inline(never)]
    fn value_slot(&mut self, max: usize) -> Option<&mut [u8]> {
        let start = self.len.checked_add(HEADER)?;
        let end = start.checked_add(max)?;
        self.buf.get_mut(start..end)
    }

    /// Writes the header of a value of `used` bytes just written.
    #[inline(never)]
    fn commit(&mut self, id: u8, used: usize) {
        let (Ok(len), Some(header)) = (
            u8::try_from(used),
            self.buf.get_mut(self.len..self.len + HEADER),
        ) else {
            self.full = true;
            return;
        };
        header.copy_from_slice(&[id, len]);
        self.len += HEADER + used;
    }

    /// The bytes written, or [`EncodeError::TooLong`] if an entry did not
    /// fit.
    pub(super) const fn finish(self) -> Result<usize, EncodeError> {
        if self.full {
            Err(EncodeError::TooLong)
        } else {
            Ok(self.len)
        }
    }
}

/// The entries of `bytes` in order, as `(id, value)`; an entry cut short
/// (its header or its value past the end) is [`Truncated`] and ends them.
pub(super) struct Entries<'a>(&'a [u8]);

impl<'a> Entries<'a> {
    pub(super) const fn new(bytes: &'a [u8]) -> Self {
        Self(bytes)
    }
}

/// An entry runs past the end of the record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Truncated;

/// A field's id and its value's bytes, or where the entries broke off.
pub(super) type Entry<'a> = Result<(u8, &'a [u8]), Truncated>;

impl<'a> Iterator for Entries<'a> {
    type Item = Entry<'a>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.0.is_empty() {
            return None;
        }
        let entry = self
            .0
            .split_first_chunk::<HEADER>()
            .and_then(|(&[id, len], rest)| {
                let (value, rest) = rest.split_at_checked(len.into())?;
                Some((id, value, rest))
            });
        let Some((id, value, rest)) = entry else {
            self.0 = &[];
            return Some(Err(Truncated));
        };
        self.0 = rest;
        Some(Ok((id, value)))
    }
}

/// `value` into `out`, its length.
#[inline(never)]
pub(super) fn put(out: &mut [u8], value: &[u8]) -> usize {
    if let Some(slot) = out.get_mut(..value.len()) {
        slot.copy_from_slice(value);
    }
    value.len()
}

/// The `u32` of exactly four little-endian bytes.
#[inline(never)]
pub(super) fn u32_of(bytes: &[u8]) -> Option<u32> {
    <[u8; 4]>::try_from(bytes).ok().map(u32::from_le_bytes)
}

/// The one byte of `bytes`.
pub(super) fn u8_of(bytes: &[u8]) -> Option<u8> {
    match bytes {
        [b] => Some(*b),
        _ => None,
    }
}

impl FieldValue for u32 {
    const MAX_LEN: usize = 4;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        put(out, &self.to_le_bytes())
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        u32_of(bytes)
    }
}

/// Units that are a `u32`: four little-endian bytes.
macro_rules! u32_units {
    ($($unit:ty),+) => {$(
        impl FieldValue for $unit {
            const MAX_LEN: usize = 4;

            fn to_bytes(&self, out: &mut [u8]) -> usize {
                self.0.to_bytes(out)
            }

            fn from_bytes(bytes: &[u8]) -> Option<Self> {
                u32_of(bytes).map(Self)
            }
        }
    )+};
}

u32_units!(
    Microseconds,
    Millis,
    NanosPerDegree,
    MilliHertz,
    DegreesPerSecond,
    DegreesPerSecondSquared
);

/// Millidegrees, four little-endian bytes (two's complement).
impl FieldValue for Angle {
    const MAX_LEN: usize = 4;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        self.millidegrees().cast_unsigned().to_bytes(out)
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        u32_of(bytes).map(|v| Self::from_millidegrees(v.cast_signed()))
    }
}

impl FieldValue for u8 {
    const MAX_LEN: usize = 1;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        put(out, &[*self])
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        u8_of(bytes)
    }
}

/// One byte, 0 to 100.
impl FieldValue for Percent {
    const MAX_LEN: usize = 1;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        self.get().to_bytes(out)
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        u8_of(bytes).and_then(Self::new)
    }
}

/// One byte: 0 normal, 1 reversed.
impl FieldValue for Direction {
    const MAX_LEN: usize = 1;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        let byte: u8 = match self {
            Self::Normal => 0,
            Self::Reversed => 1,
        };
        byte.to_bytes(out)
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        match u8_of(bytes)? {
            0 => Some(Self::Normal),
            1 => Some(Self::Reversed),
            _ => None,
        }
    }
}

/// Five bytes: 0 and the milliseconds of a return, or 1 and four zero
/// bytes for `stay`.
impl FieldValue for Hold {
    const MAX_LEN: usize = 5;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        let (tag, ms) = match self {
            Self::Return(ms) => (0_u8, ms.0),
            Self::Stay => (1, 0),
        };
        let [a, b, c, d] = ms.to_le_bytes();
        put(out, &[tag, a, b, c, d])
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let (&tag, ms) = bytes.split_first()?;
        match (tag, u32_of(ms)?) {
            (0, ms) => Some(Self::Return(Millis(ms))),
            (1, 0) => Some(Self::Stay),
            _ => None,
        }
    }
}

/// One byte: 0 off, 1 on.
impl FieldValue for bool {
    const MAX_LEN: usize = 1;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        u8::from(*self).to_bytes(out)
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        match u8_of(bytes)? {
            0 => Some(false),
            1 => Some(true),
            _ => None,
        }
    }
}

/// Two little-endian bytes, 1 to 503.
impl FieldValue for DmxAddress {
    const MAX_LEN: usize = 2;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        put(out, &self.get().to_le_bytes())
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let pair = <[u8; 2]>::try_from(bytes).ok()?;
        Self::new(u16::from_le_bytes(pair))
    }
}

/// Four little-endian bytes (two's complement).
impl FieldValue for crate::units::Millimetres {
    const MAX_LEN: usize = 4;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        self.0.cast_unsigned().to_bytes(out)
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        u32_of(bytes).map(|v| Self(v.cast_signed()))
    }
}

/// One byte: 0 the board's id, 1 the paper's, 2 chosen.
impl FieldValue for crate::seed::Seeding {
    const MAX_LEN: usize = 1;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        let byte: u8 = match self {
            Self::Board => 0,
            Self::Paper => 1,
            Self::Chosen => 2,
        };
        byte.to_bytes(out)
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        match u8_of(bytes)? {
            0 => Some(Self::Board),
            1 => Some(Self::Paper),
            2 => Some(Self::Chosen),
            _ => None,
        }
    }
}

/// One byte: 0 nearest, 1 newest.
impl FieldValue for crate::track::Prefer {
    const MAX_LEN: usize = 1;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        u8::from(*self == Self::Newest).to_bytes(out)
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        match u8_of(bytes)? {
            0 => Some(Self::Nearest),
            1 => Some(Self::Newest),
            _ => None,
        }
    }
}

/// Two little-endian bytes, the rate in Hz (50 to 333).
impl FieldValue for ServoRate {
    const MAX_LEN: usize = 2;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        put(out, &self.hz().to_le_bytes())
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let pair = <[u8; 2]>::try_from(bytes).ok()?;
        Self::new(u16::from_le_bytes(pair))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bytes_of<T: FieldValue>(value: &T) -> Vec<u8> {
        let mut out = [0xee; 8];
        let n = value.to_bytes(&mut out);
        assert!(n <= T::MAX_LEN);
        out[..n].to_vec()
    }

    /// Each type's bytes, and what is refused.
    #[test]
    fn values_and_their_bytes() {
        assert_eq!(bytes_of(&Microseconds(1500)), [0xdc, 0x05, 0, 0]);
        assert_eq!(
            bytes_of(&Angle::from_millidegrees(-2)),
            [0xfe, 0xff, 0xff, 0xff]
        );
        assert_eq!(
            Angle::from_bytes(&[0xfe, 0xff, 0xff, 0xff]),
            Some(Angle::from_millidegrees(-2))
        );
        assert_eq!(bytes_of(&Hold::Stay), [1, 0, 0, 0, 0]);
        assert_eq!(bytes_of(&Hold::Return(Millis(258))), [0, 2, 1, 0, 0]);
        assert_eq!(
            Hold::from_bytes(&[0, 2, 1, 0, 0]),
            Some(Hold::Return(Millis(258)))
        );
        assert_eq!(Hold::from_bytes(&[1, 0, 0, 0, 0]), Some(Hold::Stay));
        assert_eq!(Hold::from_bytes(&[1, 1, 0, 0, 0]), None);
        assert_eq!(Hold::from_bytes(&[2, 0, 0, 0, 0]), None);
        assert_eq!(Hold::from_bytes(&[0, 0, 0, 0]), None);
        assert_eq!(Percent::from_bytes(&[100]), Percent::new(100));
        assert_eq!(Percent::from_bytes(&[101]), None);
        assert_eq!(Direction::from_bytes(&[1]), Some(Direction::Reversed));
        assert_eq!(Direction::from_bytes(&[2]), None);
        assert_eq!((bytes_of(&true), bytes_of(&false)), (vec![1], vec![0]));
        assert_eq!(bool::from_bytes(&[2]), None);
        assert_eq!(bytes_of(&DmxAddress::LAST), [0xf7, 1]);
        assert_eq!(DmxAddress::from_bytes(&[0xf7, 1]), Some(DmxAddress::LAST));
        assert_eq!(DmxAddress::from_bytes(&[0xf8, 1]), None);
        assert_eq!(DmxAddress::from_bytes(&[0, 0]), None);
        assert_eq!(DmxAddress::from_bytes(&[1]), None);
        // A wrong length is refused, never read in part.
        assert_eq!(Millis::from_bytes(&[1, 0, 0]), None);
        assert_eq!(Millis::from_bytes(&[1, 0, 0, 0, 0]), None);
        assert_eq!(u8::from_bytes(&[]), None);
        assert_eq!(u8::from_bytes(&[1, 2]), None);
    }

    #[test]
    fn entries_round_trip_and_a_cut_entry_ends_them() {
        let mut buf = [0; 16];
        let mut w = Writer::new(&mut buf);
        w.field(7, &Millis(1));
        w.field(200, &Percent::HALF);
        let n = w.finish().unwrap();
        assert_eq!(buf[..n], [7, 4, 1, 0, 0, 0, 200, 1, 50]);
        let all: Vec<_> = Entries::new(&buf[..n]).collect();
        assert_eq!(all, [Ok((7, &[1, 0, 0, 0][..])), Ok((200, &[50][..]))]);
        for cut in 1..n {
            let entries: Vec<_> = Entries::new(&buf[..cut]).collect();
            if cut == 6 {
                assert_eq!(entries, [Ok((7, &[1, 0, 0, 0][..]))]);
            } else {
                assert_eq!(entries.last(), Some(&Err(Truncated)), "cut at {cut}");
            }
        }
        // An empty value is an entry.
        assert_eq!(
            Entries::new(&[3, 0]).collect::<Vec<_>>(),
            [Ok((3, &[][..]))]
        );
    }

    #[test]
    fn a_full_buffer_is_too_long_never_overrun() {
        for size in 0..=9 {
            let mut buf = vec![0; size];
            let mut w = Writer::new(&mut buf);
            w.field(1, &Millis(1));
            w.field(2, &Percent::HALF);
            let expected = if size >= 9 {
                Ok(9)
            } else {
                Err(EncodeError::TooLong)
            };
            assert_eq!(w.finish(), expected, "{size} bytes");
        }
    }
}
