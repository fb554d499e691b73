//! The migration from layout version 1: its fixed layout read as the
//! entries of the tagged fields it held.
//!
//! Version 1 (192 bytes) was the values of fields 1 to 56, one after the
//! other, each in the encoding its field still has, with no ids and no
//! lengths. Its layout is frozen here as the length of each field; what
//! each field means comes from the table, as for a record of today's
//! layout (a field since removed from the table is skipped as unknown).

use super::record::DecodeError;
use super::tlv::{Entry, Truncated};

/// The bytes of fields 1, 2, 3, … of a version 1 record, in order.
const LENS: [u8; 56] = [
    // Each servo, pitch, roll, yaw: neutral, per degree, direction, min,
    // max, limit min, limit max.
    4, 4, 1, 4, 4, 4, 4, //
    4, 4, 1, 4, 4, 4, 4, //
    4, 4, 1, 4, 4, 4, 4, //
    // Nod, shake, tilt: amplitude, cycles, slow, brisk, intensity.
    4, 1, 4, 4, 1, //
    4, 1, 4, 4, 1, //
    4, 1, 4, 4, 1, //
    // Max frequency, longest gesture, blend.
    4, 4, 4, //
    // Gaze: base, per degree, hold, longest.
    4, 4, 5, 4, //
    // Idle: amplitude, duck, fade.
    1, 1, 4, //
    // Gesture limits per axis: speed, acceleration.
    4, 4, 4, 4, 4, 4, //
    // Settle, the three seeds.
    4, 4, 4, 4,
];

/// Bytes of a version 1 record.
pub(super) const V1_LEN: usize = {
    let mut sum = 0;
    let mut i = 0;
    while i < LENS.len() {
        sum += LENS[i] as usize;
        i += 1;
    }
    sum
};

const _: () = assert!(V1_LEN == 192);

/// The fields of a version 1 record, as `(id, value)`.
///
/// # Errors
/// [`DecodeError::Malformed`] if `bytes` are not 192 long.
pub(super) fn entries<I>(bytes: &[u8]) -> Result<impl Iterator<Item = Entry<'_>>, DecodeError<I>> {
    if bytes.len() != V1_LEN {
        return Err(DecodeError::Malformed);
    }
    let mut rest = bytes;
    Ok((1..).zip(LENS).map(move |(id, len)| {
        let (value, after) = rest.split_at_checked(len.into()).ok_or(Truncated)?;
        rest = after;
        Ok((id, value))
    }))
}
