//! The Raspberry Pi Pico 2 image (boards/pico2, RP2350): where its boot
//! ROM finds it, its memory, its UF2. The boot ROM has no second stage to
//! load: it searches the first 4 KiB of flash for a block that declares
//! the image (an `IMAGE_DEF`, which embassy-rp links into `.start_block`).
//! No emulator runs this image: these checks are all that is known of it
//! before it meets a board.

use anyhow::{Context, Result};

use crate::{board::Board, elf, project, uf2};

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
