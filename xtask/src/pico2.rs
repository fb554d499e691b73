//! The Raspberry Pi Pico 2 image (boards/pico2, RP2350): where its boot
//! ROM finds it, its memory, its UF2. The boot ROM has no second stage to
//! load: it searches the first 4 KiB of flash for a block that declares
//! the image (an `IMAGE_DEF`, which embassy-rp links into `.start_block`).
//! No emulator runs this image: these checks are all that is known of it
//! before it meets a board.

use std::{ops::Range, path::Path};

use anyhow::{Context, Result, bail};
use object::{Object, ObjectSection};

use crate::{board::Board, elf, project::Metadata, uf2};

/// Where the vector table must be: the start of flash.
const VECTOR_TABLE: u64 = 0x1000_0000;
/// Where the boot ROM searches for the image's first block.
const BLOCK_SEARCH: Range<u64> = 0x1000_0000..0x1000_1000;
/// A block's first and last words (`PICOBIN_BLOCK_MARKER_START`, `_END`).
const MARKERS: (u32, u32) = (0xffff_ded3, 0xab12_3579);

/// The name of the stage of `cargo xtask test` that builds the Pico 2
/// image and makes its UF2.
pub const STAGE: &str = "Pico 2 build (boards/pico2): start block, settings sectors clear, UF2 \
                         family RP2350 Arm Secure";

/// The stage [`STAGE`]: builds the image, checks it and makes its UF2.
pub fn test(metadata: &Metadata) -> Result<()> {
    let board = Board::Pico2;
    board.build()?;
    let path = board.elf(metadata);
    check(&path)?;
    let (uf2, bytes) = uf2::write(&path, board, "uf2")?;
    println!("  {}", uf2::describe(&uf2, board, &bytes));
    Ok(())
}

/// The addresses of the `.start_block` section of the ELF `data`, checked:
/// inside the boot ROM's search window, opening and closing with the block
/// markers.
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
        let w = bytes.get(at..at + 4)?;
        Some(u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
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

/// Prints the image's sections and sizes; fails unless the vector table is
/// at the start of flash, a whole block lies in the first 4 KiB, the
/// settings sectors are reserved and clear, and no allocator is linked.
pub fn check(path: &Path) -> Result<()> {
    let image = elf::Image::read(path)?;
    println!("{}", path.display());
    print!("{}", image.table());
    println!(
        "  flash {} B, static RAM {} B (.radar_ring + .data + .bss + .uninit)",
        image.flash(),
        image.static_ram()
    );
    let mut problems = Vec::new();
    match image.section(".vector_table") {
        Some(table) if table.address == VECTOR_TABLE => {}
        Some(table) => problems.push(format!(
            "`.vector_table` is at {:#010x}; the RP2350 starts the image from {VECTOR_TABLE:#010x}",
            table.address
        )),
        None => problems.push("no `.vector_table` section".to_owned()),
    }
    let data = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    match start_block(&data) {
        Ok(block) => println!(
            "  start block: {} B at {:#010x}",
            block.end - block.start,
            block.start
        ),
        Err(error) => problems.push(format!("{error:#}")),
    }
    if let Err(error) = elf::check_settings_region(&image, Board::Pico2.settings()) {
        problems.push(error.to_string());
    }
    if let Err(error) = image.check_no_allocator() {
        problems.push(error.to_string());
    }
    if problems.is_empty() {
        Ok(())
    } else {
        bail!("{}", problems.join("; "))
    }
}
