//! Reads a UF2 file back, as the specification lays it out, and checks it
//! against the ELF it was made from: written from the specification, apart
//! from the crate that writes the file, so that each checks the other.
//!
//! A UF2 file is a run of 512-byte blocks, each on its own: eight
//! little-endian words of header (two magic numbers, flags, target address,
//! payload size, block number, number of blocks, family ID), 476 bytes of
//! data of which the payload is the start, and a final magic number.

use std::ops::Range;

use super::problem::Problem;
use crate::board::Board;
use crate::elf::Segment;

pub use super::sizes::{BLOCK_SIZE, PAYLOAD_SIZE};
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
