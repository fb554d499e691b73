//! Why an ELF cannot become a UF2, or a UF2 read back is not the ELF's: the
//! one error type of the writer's checks and the reader's.

use std::fmt;

use super::sizes::{BLOCK_SIZE, PAYLOAD_SIZE};

use std::ops::Range;

/// Why an ELF cannot become a UF2, or a UF2 is not the ELF's.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Problem {
    /// Not a 32-bit little-endian Arm ELF (the parser's words).
    NotElf(String),
    /// No loadable segment has contents.
    NoContents,
    /// A segment's contents lie outside the board's flash (a RAM image, or
    /// an image linked for another board).
    OutsideFlash {
        /// Load addresses of the segment.
        segment: Range<u32>,
        /// The board's flash.
        flash: Range<u32>,
    },
    /// A segment's contents reach into the settings sectors.
    InSettings {
        /// Load addresses of the segment.
        segment: Range<u32>,
        /// The settings sectors.
        settings: Range<u32>,
    },
    /// Two segments load to the same flash.
    Overlap {
        /// The lower segment.
        first: Range<u32>,
        /// The one that starts inside it.
        second: Range<u32>,
    },
    /// The file is empty or not a whole number of blocks.
    Length(usize),
    /// A block's magic numbers are wrong.
    Magic {
        /// Block index in the file.
        block: usize,
    },
    /// A block has no family ID.
    NoFamily {
        /// Block index in the file.
        block: usize,
    },
    /// A block is for another chip.
    Family {
        /// Block index in the file.
        block: usize,
        /// Its family.
        found: u32,
        /// The board's.
        expected: u32,
    },
    /// A block's payload is not one 256-byte page.
    PayloadSize {
        /// Block index in the file.
        block: usize,
        /// Its payload size.
        found: u32,
    },
    /// A block's number is not its place in the file.
    Numbering {
        /// Block index in the file.
        block: usize,
        /// The number it carries.
        found: u32,
    },
    /// A block's total is not the number of blocks in the file.
    Total {
        /// Block index in the file.
        block: usize,
        /// The total it carries.
        found: u32,
        /// Blocks in the file.
        expected: usize,
    },
    /// A block's address is not page-aligned.
    Unaligned {
        /// Block index in the file.
        block: usize,
        /// Its address.
        address: u32,
    },
    /// A block writes outside the board's flash or into its settings.
    NotImageFlash {
        /// Block index in the file.
        block: usize,
        /// Its address.
        address: u32,
    },
    /// The first block is not at the start of flash, where the boot ROM
    /// looks for the image.
    Start {
        /// The first block's address.
        address: u32,
        /// The start of the board's flash.
        expected: u32,
    },
    /// A block does not follow on from the one before: a hole, a block out
    /// of order, or one twice.
    Gap {
        /// Block index in the file.
        block: usize,
        /// Its address.
        address: u32,
        /// The address that would follow on.
        expected: u32,
    },
    /// A byte of a segment is not in any block.
    Uncovered {
        /// Its load address.
        address: u32,
    },
    /// A byte differs from the ELF (a segment's, or zero between segments).
    Bytes {
        /// Its flash address.
        address: u32,
        /// In the UF2.
        found: u8,
        /// In the ELF.
        expected: u8,
    },
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotElf(error) => write!(f, "not a 32-bit little-endian Arm ELF: {error}"),
            Self::NoContents => write!(f, "the ELF has no loadable contents"),
            Self::OutsideFlash { segment, flash } => write!(
                f,
                "a segment loads to {}, outside the board's flash {} (an image for another \
                 board, or one that runs from RAM?)",
                hex(segment),
                hex(flash)
            ),
            Self::InSettings { segment, settings } => write!(
                f,
                "a segment loads to {}, into the settings sectors {}: flashing it would \
                 overwrite the saved settings",
                hex(segment),
                hex(settings)
            ),
            Self::Overlap { first, second } => write!(
                f,
                "two segments load to the same flash: {} and {}",
                hex(first),
                hex(second)
            ),
            Self::Length(length) => write!(
                f,
                "{length} bytes is not a whole, non-zero number of {BLOCK_SIZE}-byte blocks"
            ),
            Self::Magic { block } => write!(f, "block {block}: wrong magic numbers"),
            Self::NoFamily { block } => write!(f, "block {block}: no family ID flag"),
            Self::Family {
                block,
                found,
                expected,
            } => write!(
                f,
                "block {block}: family {found:#010x}, the board's boot ROM takes {expected:#010x}"
            ),
            Self::PayloadSize { block, found } => write!(
                f,
                "block {block}: a payload of {found} bytes, the boot ROM writes {PAYLOAD_SIZE}"
            ),
            Self::Numbering { block, found } => write!(f, "block {block} carries number {found}"),
            Self::Total {
                block,
                found,
                expected,
            } => write!(
                f,
                "block {block} says the file has {found} blocks; it has {expected}"
            ),
            Self::Unaligned { block, address } => write!(
                f,
                "block {block}: address {address:#010x} is not on a {PAYLOAD_SIZE}-byte page"
            ),
            Self::NotImageFlash { block, address } => write!(
                f,
                "block {block}: address {address:#010x} is outside the board's flash for images"
            ),
            Self::Start { address, expected } => write!(
                f,
                "the first block is at {address:#010x}; the image must start at {expected:#010x}"
            ),
            Self::Gap {
                block,
                address,
                expected,
            } => write!(
                f,
                "block {block} is at {address:#010x}, not {expected:#010x} right after the one \
                 before"
            ),
            Self::Uncovered { address } => {
                write!(f, "the ELF's byte at {address:#010x} is in no block")
            }
            Self::Bytes {
                address,
                found,
                expected,
            } => write!(
                f,
                "the byte at {address:#010x} is {found:#04x} in the UF2, {expected:#04x} in the ELF"
            ),
        }
    }
}

impl std::error::Error for Problem {}

/// `range` in hexadecimal, as the messages show addresses.
fn hex(range: &Range<u32>) -> String {
    format!("{:#010x}..{:#010x}", range.start, range.end)
}
