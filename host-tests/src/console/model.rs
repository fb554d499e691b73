//! A reference line discipline written the plain way (growable vectors,
//! whole stream at once), to check the framer against, and the line ends
//! of a stream counted on their own.

use idle_head_core::console::LineError;

/// Line ends in `stream`: every CR, and every LF not right after a CR.
#[must_use]
pub fn count_line_ends(stream: &[u8]) -> usize {
    let mut previous = 0;
    let mut ends = 0;
    for &b in stream {
        if b == b'\r' || (b == b'\n' && previous != b'\r') {
            ends += 1;
        }
        previous = b;
    }
    ends
}

/// The outcome of every completed line of `stream` for a buffer of `max`
/// bytes, as the protocol defines it.
#[must_use]
pub fn reference_lines(stream: &[u8], max: usize) -> Vec<Result<Vec<u8>, LineError>> {
    let mut lines = Vec::new();
    let mut raw = Vec::new();
    let mut previous = 0;
    for &b in stream {
        match b {
            b'\n' if previous == b'\r' => {}
            b'\r' | b'\n' => lines.push(judge(&std::mem::take(&mut raw), max)),
            _ => raw.push(b),
        }
        previous = b;
    }
    lines
}

/// One line's bytes as received (no line end) → its outcome.
fn judge(raw: &[u8], max: usize) -> Result<Vec<u8>, LineError> {
    let mut line: Vec<u8> = Vec::new();
    for (i, &b) in raw.iter().enumerate() {
        if b == 0x08 || b == 0x7f {
            delete_char(&mut line);
        } else if line.len() == max {
            // Full, and one more byte: everything from here on is lost.
            return Err(LineError::TooLong {
                len: max + raw.len() - i,
                max,
            });
        } else {
            line.push(b);
        }
    }
    if let Some(at) = line.iter().position(|&b| b < 0x20 && b != b'\t') {
        return Err(LineError::Control { at, byte: line[at] });
    }
    match std::str::from_utf8(&line) {
        Ok(_) => Ok(line),
        Err(e) => Err(LineError::NotUtf8 {
            at: e.valid_up_to(),
        }),
    }
}

/// What a backspace deletes: a whole UTF-8 sequence (lead byte and up to
/// three continuation bytes that it announces), else one byte.
fn delete_char(line: &mut Vec<u8>) {
    let trailing = line.iter().rev().take_while(|&&b| b & 0xc0 == 0x80).count();
    let width = |lead: u8| match lead {
        0xc0..=0xdf => 2,
        0xe0..=0xef => 3,
        0xf0..=0xf7 => 4,
        _ => 1,
    };
    let whole = trailing <= 3
        && line
            .len()
            .checked_sub(trailing + 1)
            .is_some_and(|lead| trailing < width(line[lead]));
    let n = if whole { trailing + 1 } else { 1 };
    line.truncate(line.len().saturating_sub(n));
}
