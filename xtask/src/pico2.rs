//! The Raspberry Pi Pico 2 image (boards/pico2, RP2350): where its boot
//! ROM finds it, its memory, its UF2.
//!
//! The RP2350 boot ROM has no second stage to load. It searches the first
//! 4 KiB of flash for a block, between the markers `0xffffded3` and
//! `0xab123579`, that declares the image (an `IMAGE_DEF`: embassy-rp links
//! one into `.start_block`), and starts it from the vector table at the
//! start of flash. No emulator runs this image here: these checks are all
//! that is known of it before it meets a board.

use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::rp2350::{BLOCK_MARKER_END, BLOCK_MARKER_START, start_block};
use crate::{board::Board, elf, project::Metadata, uf2};

/// Where the vector table must be: the start of flash.
pub const VECTOR_TABLE: u64 = 0x1000_0000;

/// The name of the stage of `cargo xtask test` that builds the Pico 2
/// image and makes its UF2.
pub const STAGE: &str = "Pico 2 build (boards/pico2): start block, settings sectors clear, UF2 \
                         family RP2350 Arm Secure";

/// The stage [`STAGE`]: builds the image, checks it and makes its UF2.
///
/// # Errors
/// If the build fails, the image is misplaced, or its UF2 cannot be made.
pub fn test(metadata: &Metadata) -> Result<()> {
    let board = Board::Pico2;
    board.build()?;
    let path = board.elf(metadata);
    check(&path)?;
    let (uf2, made) = uf2::write(&path, board)?;
    println!("  {}", uf2::describe(&uf2, board, &made.layout));
    Ok(())
}

/// Prints the image's sections and sizes; fails unless the vector table is
/// at the start of flash, a whole block lies in the first 4 KiB, the
/// settings sectors are reserved and clear, and no allocator is linked.
///
/// # Errors
/// The problems found, all of them.
pub fn check(path: &Path) -> Result<()> {
    let image = elf::Image::read(path)?;
    println!("{}", path.display());
    print!("{}", image.table());
    println!(
        "  flash {} B, static RAM {} B (.data + .bss + .uninit)",
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
            "  start block: {} B at {:#010x}, markers {BLOCK_MARKER_START:#010x} .. \
             {BLOCK_MARKER_END:#010x}",
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
