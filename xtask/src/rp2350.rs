//! What the RP2350 boot ROM reads of an image: the block in the first
//! 4 KiB of flash that declares it (an `IMAGE_DEF`: embassy-rp links one
//! into `.start_block`). Read by the Pico 2 stage and by the UF2 writer,
//! which refuses an image the board could not start.

use std::ops::Range;

use anyhow::{Context, Result, bail};
use object::{Object, ObjectSection};

/// Where the boot ROM searches for the image's first block: the first
/// 4 KiB of flash.
pub const BLOCK_SEARCH: Range<u64> = 0x1000_0000..0x1000_1000;
/// A block's first word (`PICOBIN_BLOCK_MARKER_START`).
pub const BLOCK_MARKER_START: u32 = 0xffff_ded3;
/// A block's last word (`PICOBIN_BLOCK_MARKER_END`).
pub const BLOCK_MARKER_END: u32 = 0xab12_3579;

/// The addresses of the `.start_block` section of the ELF `data`, checked:
/// inside the boot ROM's search window, opening and closing with the block
/// markers.
///
/// # Errors
/// If there is no such section, or it is misplaced or not a block.
pub fn start_block(data: &[u8]) -> Result<Range<u64>> {
    let file = object::File::parse(data).context("parsing the ELF")?;
    let section = file.section_by_name(".start_block").context(
        "no `.start_block` section: the RP2350 boot ROM would not find the image (does memory.x \
         place `.start_block`, and does embassy-rp link its IMAGE_DEF?)",
    )?;
    let range = section.address()..section.address() + section.size();
    if range.start < BLOCK_SEARCH.start || range.end > BLOCK_SEARCH.end {
        bail!(
            "`.start_block` is at {:#010x}..{:#010x}, outside the first 4 KiB of flash where the \
             boot ROM searches",
            range.start,
            range.end
        );
    }
    let bytes = section.data().context("reading `.start_block`")?;
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let last = bytes.len().checked_sub(4);
    if word(0) != Some(BLOCK_MARKER_START) || last.and_then(word) != Some(BLOCK_MARKER_END) {
        bail!(
            "`.start_block` ({} B) does not open with {BLOCK_MARKER_START:#010x} and close with \
             {BLOCK_MARKER_END:#010x}: not a block the boot ROM reads",
            bytes.len()
        );
    }
    Ok(range)
}
