//! Reads a UF2 file back, as the specification lays it out, and checks it
//! against the ELF it was made from: written from the specification, apart
//! from the crate that writes the file, so that each checks the other.
//!
//! A UF2 file is a run of 512-byte blocks, each on its own: eight
//! little-endian words of header (two magic numbers, flags, target address,
//! payload size, block number, number of blocks, family ID), 476 bytes of
//! data of which the payload is the start, and a final magic number.

use std::{fmt, ops::Range};

use super::segments::Segment;
use crate::board::Board;

/// Size of a block.
pub const BLOCK_SIZE: usize = 512;
/// Bytes of each block's data that the RP2040 and RP2350 boot ROMs write:
/// one flash page, at a page-aligned address.
pub const PAYLOAD_SIZE: u32 = 256;
/// First magic number, `"UF2\n"`.
pub const MAGIC_START0: u32 = 0x0a32_4655;
/// Second magic number.
pub const MAGIC_START1: u32 = 0x9e5d_5157;
/// Final magic number, the block's last word.
pub const MAGIC_END: u32 = 0x0ab1_6f30;
/// Flag: the last header word is a family ID (not a file size).
pub const FLAG_FAMILY_ID_PRESENT: u32 = 0x0000_2000;

/// One block as read from the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Block {
    /// Flags word.
    pub flags: u32,
    /// Flash address of the payload's first byte.
    pub address: u32,
    /// Payload size, bytes.
    pub payload_size: u32,
    /// Block number, from 0.
    pub number: u32,
    /// Number of blocks in the file, as this block says.
    pub total: u32,
    /// Family ID (with [`FLAG_FAMILY_ID_PRESENT`]).
    pub family: u32,
    /// The payload: the first `payload_size` bytes of the data.
    pub payload: Vec<u8>,
}

/// What a checked UF2 file holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// Number of blocks.
    pub blocks: usize,
    /// Flash the blocks cover, contiguous.
    pub flash: Range<u32>,
    /// Bytes of the ELF's loadable segments in it.
    pub loaded: usize,
    /// The family of every block.
    pub family: u32,
}

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

fn hex(range: &Range<u32>) -> String {
    format!("{:#010x}..{:#010x}", range.start, range.end)
}

fn word(bytes: &[u8], at: usize) -> u32 {
    let mut le = [0; 4];
    le.copy_from_slice(&bytes[at..at + 4]);
    u32::from_le_bytes(le)
}

/// Reads every block of `file`.
///
/// # Errors
/// A [`Problem`] if the file is not whole blocks, a block's magic numbers,
/// numbering or total are wrong, it has no family ID, or its payload is not
/// one page.
pub fn parse(file: &[u8]) -> Result<Vec<Block>, Problem> {
    if file.is_empty() || !file.len().is_multiple_of(BLOCK_SIZE) {
        return Err(Problem::Length(file.len()));
    }
    let count = file.len() / BLOCK_SIZE;
    let mut blocks = Vec::with_capacity(count);
    for (index, raw) in file.chunks_exact(BLOCK_SIZE).enumerate() {
        if word(raw, 0) != MAGIC_START0
            || word(raw, 4) != MAGIC_START1
            || word(raw, BLOCK_SIZE - 4) != MAGIC_END
        {
            return Err(Problem::Magic { block: index });
        }
        let flags = word(raw, 8);
        if flags & FLAG_FAMILY_ID_PRESENT == 0 {
            return Err(Problem::NoFamily { block: index });
        }
        let payload_size = word(raw, 16);
        if payload_size != PAYLOAD_SIZE {
            return Err(Problem::PayloadSize {
                block: index,
                found: payload_size,
            });
        }
        let number = word(raw, 20);
        if usize::try_from(number).ok() != Some(index) {
            return Err(Problem::Numbering {
                block: index,
                found: number,
            });
        }
        let total = word(raw, 24);
        if usize::try_from(total).ok() != Some(count) {
            return Err(Problem::Total {
                block: index,
                found: total,
                expected: count,
            });
        }
        blocks.push(Block {
            flags,
            address: word(raw, 12),
            payload_size,
            number,
            total,
            family: word(raw, 28),
            payload: raw[32..32 + PAYLOAD_SIZE as usize].to_vec(),
        });
    }
    Ok(blocks)
}

/// Checks that `blocks` are the flash image of `segments` for `board`: all
/// of the board's family, page-aligned, contiguous from the start of its
/// flash and clear of its settings, every byte a segment's or, between
/// segments, zero.
///
/// # Errors
/// The first [`Problem`] found.
pub fn check(blocks: &[Block], board: Board, segments: &[Segment]) -> Result<Layout, Problem> {
    let flash = board.flash();
    let settings = board.settings();
    let mut expected_address = flash.start;
    for (index, block) in blocks.iter().enumerate() {
        if block.family != board.family_id() {
            return Err(Problem::Family {
                block: index,
                found: block.family,
                expected: board.family_id(),
            });
        }
        if !block.address.is_multiple_of(PAYLOAD_SIZE) {
            return Err(Problem::Unaligned {
                block: index,
                address: block.address,
            });
        }
        let end = block.address.checked_add(PAYLOAD_SIZE);
        if block.address < flash.start || end.is_none_or(|end| end > settings.start) {
            return Err(Problem::NotImageFlash {
                block: index,
                address: block.address,
            });
        }
        if index == 0 && block.address != flash.start {
            return Err(Problem::Start {
                address: block.address,
                expected: flash.start,
            });
        }
        if block.address != expected_address {
            return Err(Problem::Gap {
                block: index,
                address: block.address,
                expected: expected_address,
            });
        }
        expected_address += PAYLOAD_SIZE;
    }
    let covered = flash.start..expected_address;

    // The flash as the ELF has it: zero where no segment loads.
    let mut image = vec![0_u8; (covered.end - covered.start) as usize];
    let mut loaded = 0;
    for segment in segments {
        for (address, &byte) in (segment.address..).zip(&segment.data) {
            if !covered.contains(&address) {
                return Err(Problem::Uncovered { address });
            }
            image[(address - covered.start) as usize] = byte;
        }
        loaded += segment.data.len();
    }
    let written = blocks.iter().flat_map(|block| block.payload.iter());
    for ((address, &found), &expected) in (covered.start..).zip(written).zip(&image) {
        if found != expected {
            return Err(Problem::Bytes {
                address,
                found,
                expected,
            });
        }
    }
    Ok(Layout {
        blocks: blocks.len(),
        flash: covered,
        loaded,
        family: board.family_id(),
    })
}
