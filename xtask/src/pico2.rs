//! The Raspberry Pi Pico 2 image (boards/pico2, RP2350): where its boot
//! ROM finds it, its memory, its UF2. The boot ROM has no second stage to
//! load: it searches the first 4 KiB of flash for a block that declares
//! the image (an `IMAGE_DEF`, which embassy-rp links into `.start_block`).
//! No emulator runs this image: these checks are all that is known of it
//! before it meets a board.

use std::ops::Range;

use anyhow::{Context, Result, bail};
use object::{Object, ObjectSection};

use crate::{board::Board, elf, project, uf2};

/// A block's first and last words (`PICOBIN_BLOCK_MARKER_START`, `_END`).
const MARKERS: (u32, u32) = (0xffff_ded3, 0xab12_3579);

/// The name of the stage of `cargo xtask test` that builds the Pico 2
/// image and makes its UF2.
pub const STAGE: &str = "Pico 2 build (boards/pico2): start block, settings sectors clear, UF2 \
                         family RP2350 Arm Secure";

/// The stage [`STAGE`]: builds the image and prints its sections and
/// sizes; fails unless the vector table is at the start of flash, a whole
/// block lies in the first 4 KiB, the settings sectors are reserved and
/// clear, and no allocator is linked; then makes its UF2.
pub fn test(metadata: &project::Metadata) -> Result<()> {
    let board = Board::Pico2;
    board.image().build(&project::root())?;
    let path = board.image().elf(metadata);
    let image = elf::Image::show(&path)?;
    let data = std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
    let block = start_block(&data).map(|block| {
        let size = block.end - block.start;
        println!("  start block: {size} B at {:#010x}", block.start);
    });
    project::verdict(&elf::problems([
        image.check_vector_table(elf::XIP.start, "RP2350"),
        block,
        image.check_settings_region(board),
        image.check_no_allocator(),
    ]))?;
    let (uf2, bytes) = uf2::write(&path, board, "uf2")?;
    println!("  {}", uf2::describe(&uf2, board, &bytes));
    Ok(())
}

/// The addresses of the `.start_block` section of the ELF `data`, checked:
/// inside the first 4 KiB of flash, where the boot ROM searches, opening
/// and closing with the block markers.
pub fn start_block(data: &[u8]) -> Result<Range<u64>> {
    let file = object::File::parse(data).context("parsing the ELF")?;
    let section = file.section_by_name(".start_block").context(
        "no `.start_block` section: the RP2350 boot ROM would not find the image (does memory.x \
         place `.start_block`, and does embassy-rp link its IMAGE_DEF?)",
    )?;
    let range = section.address()..section.address() + section.size();
    let search = elf::XIP.start..elf::XIP.start + 0x1000;
    if range.start < search.start || range.end > search.end {
        bail!(
            "`.start_block` is at {range:#010x?}, outside the first 4 KiB of flash where the boot \
             ROM searches"
        );
    }
    let bytes = section.data().context("reading `.start_block`")?;
    let word = |at: usize| Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?));
    let last = bytes.len().checked_sub(4).and_then(word);
    if word(0) != Some(MARKERS.0) || last != Some(MARKERS.1) {
        bail!(
            "`.start_block` ({} B) does not open with {:#010x} and close with {:#010x}: not a \
             block the boot ROM reads",
            bytes.len(),
            MARKERS.0,
            MARKERS.1
        );
    }
    Ok(range)
}
