//! The Pico 2 image (boards/pico2, RP2350): no emulator runs it, so these
//! checks are all that is known of it before it meets a board.

use anyhow::{Context, Result};

use crate::{board::Board, elf, project, uf2};

pub const STAGE: &str = "Pico 2 build (boards/pico2): start block, settings sectors clear, UF2 \
                         family RP2350 Arm Secure";

/// Builds the image, prints and checks its sections, and makes its UF2.
pub fn test(metadata: &project::Metadata) -> Result<()> {
    let board = Board::Pico2;
    board.image().build(&project::root())?;
    let path = board.image().elf(metadata);
    let image = elf::Image::show(&path)?;
    let data = std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
    let block = uf2::start_block(&data).map(|block| {
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
