//! The HLK-LD2450 24 GHz radar's report frames, decoded.
//!
//! The module sends a frame ten times a second at 256000 baud, 8N1:
//!
//! | bytes | what |
//! |---|---|
//! | 4 | header `AA FF 03 00` |
//! | 8 × 3 | a target each: x, y (mm), speed (cm/s), distance resolution (mm), 16-bit little-endian |
//! | 2 | footer `55 CC` |
//!
//! x, y and speed have the module's own sign encoding: the top bit set
//! means positive, clear means negative, and the other 15 bits are the
//! magnitude (so `0x030E` is −782 and `0x86B1` is +1713). A target of
//! eight zero bytes is an empty slot. The resolution is unsigned.
//!
//! # Resynchronisation
//!
//! The decoder looks for the header byte by byte, so it finds the next
//! frame after any garbage (a receiver started mid-frame, noise on the
//! line, a wrong baud rate), counting the bytes it skips. A frame whose
//! footer is wrong is counted bad and dropped, and the search starts
//! again at the byte after its first: a header that was really data
//! cannot hide the real one that follows. A receive error inside a frame
//! makes it bad too. Nothing here indexes out of bounds or panics on any
//! input (the frame path's link-time proof covers it).
//!
//! (A hand-written decoder rather than a crate: the frame is 30 fixed
//! bytes, and the proof needs the decoder's code free of panic paths,
//! with integer coordinates and our counters.)

use super::{Counters, PEOPLE, Person, Sighting, SightingSource};
use crate::units::Millimetres;

/// Bytes of a frame.
pub const FRAME: usize = 30;
/// The frame's first four bytes.
pub const HEADER: [u8; 4] = [0xAA, 0xFF, 0x03, 0x00];
/// The frame's last two bytes.
pub const FOOTER: [u8; 2] = [0x55, 0xCC];
/// Bytes of one target.
pub const TARGET: usize = 8;

/// One target as the radar reports it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Target {
    /// Across, mm: positive to the radar's right as seen from behind it.
    pub x: Millimetres,
    /// Away from the radar, mm.
    pub y: Millimetres,
    /// Speed along the line of sight, cm/s (negative: approaching).
    pub speed: i16,
    /// The size of the radar's distance gate, mm.
    pub resolution: u16,
}

/// A value in the module's sign encoding (top bit set: positive).
#[must_use]
pub const fn signed(raw: u16) -> i16 {
    let magnitude = (raw & 0x7FFF) as i16;
    if raw & 0x8000 != 0 {
        magnitude
    } else {
        -magnitude
    }
}

/// `value` in the module's sign encoding (the encoder the tests and the
/// emulator's harness use): the magnitude saturates at 32767.
#[must_use]
pub const fn encode(value: i32) -> u16 {
    let magnitude = if value.unsigned_abs() > 0x7FFF {
        0x7FFF
    } else {
        value.unsigned_abs() as u16
    };
    if value >= 0 {
        magnitude | 0x8000
    } else {
        magnitude
    }
}

/// The target of eight bytes, `None` for an empty slot.
#[must_use]
pub fn target(bytes: &[u8; TARGET]) -> Option<Target> {
    if bytes.iter().all(|&b| b == 0) {
        return None;
    }
    let word = |i: usize| {
        let lo = bytes.get(i).copied().unwrap_or(0);
        let hi = bytes.get(i + 1).copied().unwrap_or(0);
        u16::from_le_bytes([lo, hi])
    };
    Some(Target {
        x: Millimetres(signed(word(0)).into()),
        y: Millimetres(signed(word(2)).into()),
        speed: signed(word(4)),
        resolution: word(6),
    })
}

/// A whole frame for `targets` (the encoder of tests and the emulator's
/// harness; `None` is an empty slot).
#[must_use]
pub fn frame(targets: &[Option<Target>; PEOPLE]) -> [u8; FRAME] {
    let mut out = [0; FRAME];
    let mut at = 0;
    let mut put = |bytes: &[u8]| {
        for &b in bytes {
            if let Some(slot) = out.get_mut(at) {
                *slot = b;
            }
            at += 1;
        }
    };
    put(&HEADER);
    for t in targets {
        match t {
            Some(t) => {
                put(&encode(t.x.0).to_le_bytes());
                put(&encode(t.y.0).to_le_bytes());
                put(&encode(t.speed.into()).to_le_bytes());
                put(&t.resolution.to_le_bytes());
            }
            None => put(&[0; TARGET]),
        }
    }
    put(&FOOTER);
    out
}

/// The streaming decoder; see the [module docs](self).
///
/// ```
/// use idle_head_core::track::ld2450::Decoder;
/// use idle_head_core::track::SightingSource;
///
/// let mut radar = Decoder::new();
/// let frame = [
///     0xAA, 0xFF, 0x03, 0x00, // header
///     0x0E, 0x03, 0xB1, 0x86, 0x10, 0x00, 0x40, 0x01, // x −782, y 1713, −16 cm/s, 320 mm
///     0, 0, 0, 0, 0, 0, 0, 0, // empty
///     0, 0, 0, 0, 0, 0, 0, 0, // empty
///     0x55, 0xCC, // footer
/// ];
/// let mut seen = Vec::new();
/// radar.feed(&[0x12, 0xAA], &mut |s| seen.push(s)); // garbage first
/// radar.feed(&frame, &mut |s| seen.push(s));
/// let person = seen[0].people[0].unwrap();
/// assert_eq!((person.x.0, person.y.0), (-782, 1713));
/// assert_eq!(seen[0].count(), 1);
/// assert_eq!(radar.counters().good, 1);
/// assert_eq!(radar.counters().skipped, 2);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Decoder {
    buf: [u8; FRAME],
    /// Bytes of the frame under way in `buf`.
    len: usize,
    counters: Counters,
    last: [Option<Target>; PEOPLE],
}

impl Decoder {
    /// Looking for the first header.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            buf: [0; FRAME],
            len: 0,
            counters: Counters {
                good: 0,
                bad: 0,
                dropped: 0,
                skipped: 0,
            },
            last: [None; PEOPLE],
        }
    }

    /// The targets of the last good frame, as the radar gave them.
    #[must_use]
    pub const fn targets(&self) -> &[Option<Target>; PEOPLE] {
        &self.last
    }

    /// One byte; a whole good frame's sighting when it ends one.
    pub fn push(&mut self, byte: u8) -> Option<Sighting> {
        if self.len < HEADER.len() {
            self.header(byte);
            return None;
        }
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = byte;
        }
        self.len += 1;
        if self.len < FRAME {
            return None;
        }
        self.len = 0;
        if self.buf.get(FRAME - FOOTER.len()..) != Some(&FOOTER[..]) {
            self.counters.bad = self.counters.bad.wrapping_add(1);
            self.rescan();
            return None;
        }
        self.counters.good = self.counters.good.wrapping_add(1);
        let mut sighting = Sighting::NOBODY;
        for (i, (person, last)) in sighting
            .people
            .iter_mut()
            .zip(self.last.iter_mut())
            .enumerate()
        {
            let at = HEADER.len() + i * TARGET;
            let bytes = self
                .buf
                .get(at..at + TARGET)
                .and_then(|b| <&[u8; TARGET]>::try_from(b).ok());
            *last = bytes.and_then(target);
            *person = last.map(|t| Person { x: t.x, y: t.y });
        }
        Some(sighting)
    }

    /// A byte while the header is not complete: the header goes on, or
    /// starts again (at this byte if it is the header's first).
    fn header(&mut self, byte: u8) {
        if HEADER.get(self.len) == Some(&byte) {
            if let Some(slot) = self.buf.get_mut(self.len) {
                *slot = byte;
            }
            self.len += 1;
            return;
        }
        // The header has no part that is also its start but its first
        // byte: a mismatch can only start it again at this byte.
        self.counters.skipped = self.counters.skipped.wrapping_add(self.len as u32);
        self.len = 0;
        if byte == HEADER[0] {
            self.buf[0] = byte;
            self.len = 1;
        } else {
            self.counters.skipped = self.counters.skipped.wrapping_add(1);
        }
    }

    /// After a bad frame: looks for a header in its bytes after the first
    /// (fewer than a frame: none of them can end one).
    fn rescan(&mut self) {
        let rest = self.buf;
        // The first byte was the false header's.
        self.counters.skipped = self.counters.skipped.wrapping_add(1);
        for &b in rest.get(1..).unwrap_or_default() {
            let _ = self.push(b);
        }
    }
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl SightingSource for Decoder {
    fn feed(&mut self, input: &[u8], seen: &mut dyn FnMut(Sighting)) {
        for &b in input {
            if let Some(s) = self.push(b) {
                seen(s);
            }
        }
    }

    fn error(&mut self) {
        if self.len > 0 {
            self.counters.bad = self.counters.bad.wrapping_add(1);
            self.len = 0;
        }
    }

    fn counters(&self) -> Counters {
        self.counters
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn person(x: i32, y: i32) -> Target {
        Target {
            x: Millimetres(x),
            y: Millimetres(y),
            speed: -16,
            resolution: 320,
        }
    }

    #[test]
    fn the_sign_encoding_round_trips() {
        assert_eq!(signed(0x030E), -782);
        assert_eq!(signed(0x86B1), 1713);
        assert_eq!(signed(0x8000), 0);
        assert_eq!(signed(0x0000), 0);
        for v in [-32767, -1, 0, 1, 782, 32767] {
            assert_eq!(i32::from(signed(encode(v))), v);
        }
        assert_eq!(signed(encode(40_000)), 32767);
    }

    #[test]
    fn a_frame_round_trips_and_empty_slots_are_none() {
        let targets = [Some(person(-782, 1713)), None, Some(person(1200, 3000))];
        let bytes = frame(&targets);
        let mut d = Decoder::new();
        let got: Vec<_> = bytes.iter().filter_map(|&b| d.push(b)).collect();
        assert_eq!(got.len(), 1);
        assert_eq!(d.targets(), &targets);
        assert_eq!(got[0].count(), 2);
        assert_eq!(got[0].people[1], None);
    }

    #[test]
    fn a_false_header_in_a_bad_frame_does_not_hide_the_real_one() {
        let good = frame(&[Some(person(100, 2000)), None, None]);
        // A header, 10 bytes of it, then the real frame: the false frame's
        // 30 bytes end inside the real one.
        let mut stream = HEADER.to_vec();
        stream.extend_from_slice(&[1; 6]);
        stream.extend_from_slice(&good);
        stream.extend_from_slice(&good);
        let mut d = Decoder::new();
        let got: Vec<_> = stream.iter().filter_map(|&b| d.push(b)).collect();
        assert_eq!(d.counters().bad, 1);
        assert_eq!(got.len(), 2, "{:?}", d.counters());
    }
}
