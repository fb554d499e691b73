//! `cargo xtask uf2`: the firmware as a UF2 file for a board in BOOTSEL
//! mode, written by `elf2flash-core`. Every emulator run of the Pico image
//! boots from it (`sim/harness.mjs`): that is its test.

use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, ensure};
use object::{Object, ObjectSection};

use crate::{board::Board, elf, project};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The board the image is for.
    #[arg(long, value_enum, default_value_t = Board::Pico)]
    pub board: Board,
    /// The firmware ELF. Without it, the board's release image, built first
    /// (`cargo build --release` in the board's package).
    #[arg(value_name = "ELF")]
    pub elf: Option<PathBuf>,
}

/// A block's first and last words (`PICOBIN_BLOCK_MARKER_START`, `_END`).
const MARKERS: (u32, u32) = (0xffff_ded3, 0xab12_3579);

/// Size of a UF2 block; each carries one 256-byte flash page.
const BLOCK: usize = 512;

/// The UF2 of the ELF `elf` for `board`: refused unless it has what the
/// board's boot ROM starts, `.boot2` (Pico) or `.start_block` (Pico 2).
pub fn make(elf: &[u8], board: Board) -> Result<Vec<u8>> {
    let image = elf::Image::parse(elf).context("parsing the ELF")?;
    match board {
        Board::Pico => image.check_boot2()?,
        Board::Pico2 => start_block(elf).map(|_| ())?,
    }
    let settings = board.settings().start;
    let end = image.flash_end;
    ensure!(
        end <= settings,
        "the image's flash contents end at {end:#010x}, in the settings sectors from {settings:#010x}: flashing it would overwrite the saved settings"
    );
    let (chip, mut bytes) = (board.uf2_chip(), Vec::new());
    elf2flash_core::elf2uf2(elf, &mut bytes, chip, elf2flash_core::NoProgress)
        .context("writing the UF2 blocks")?;
    Ok(bytes)
}

/// The addresses of `.start_block` in the ELF `data`, checked: in the first
/// 4 KiB of flash, where the boot ROM searches, between the block markers.
pub fn start_block(data: &[u8]) -> Result<Range<u64>> {
    let file = object::File::parse(data).context("parsing the ELF")?;
    let section = file.section_by_name(".start_block").context(
        "no `.start_block` section: the RP2350 boot ROM would not find the image (does memory.x \
         place `.start_block`, and does embassy-rp link its IMAGE_DEF?)",
    )?;
    let range = section.address()..section.address() + section.size();
    let search = elf::XIP.start..elf::XIP.start + 0x1000;
    ensure!(
        range.start >= search.start && range.end <= search.end,
        "`.start_block` is at {range:#010x?}, outside the first 4 KiB of flash where the boot \
         ROM searches"
    );
    let bytes = section.data().context("reading `.start_block`")?;
    let word = |at: usize| Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?));
    let last = bytes.len().checked_sub(4).and_then(word);
    ensure!(
        word(0) == Some(MARKERS.0) && last == Some(MARKERS.1),
        "`.start_block` ({} B) does not open with {:#010x} and close with {:#010x}: not a \
         block the boot ROM reads",
        bytes.len(),
        MARKERS.0,
        MARKERS.1
    );
    Ok(range)
}

/// Makes the UF2 of the ELF at `elf` and writes it beside it (`…/pico` →
/// `…/pico.uf2`, or another `extension`); returns its path and contents.
pub fn write(elf: &Path, board: Board, extension: &str) -> Result<(PathBuf, Vec<u8>)> {
    let data = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let bytes = make(&data, board).with_context(|| format!("the UF2 of {}", elf.display()))?;
    let path = elf.with_extension(extension);
    project::write(&path, &bytes)?;
    Ok((path, bytes))
}

/// One line about a UF2 written to `path`.
pub fn describe(path: &Path, board: Board, bytes: &[u8]) -> String {
    format!(
        "{}: {} blocks of 256 B, family {:#010x} for the {}",
        project::relative(path).display(),
        bytes.len() / BLOCK,
        board.uf2_chip().family_id(),
        board.name()
    )
}

pub fn command(args: &Args) -> Result<bool> {
    let elf = if let Some(elf) = &args.elf {
        elf.clone()
    } else {
        let (root, metadata) = crate::setup::prepare()?;
        args.board.image().build(&root)?;
        args.board.image().elf(&metadata)
    };
    let board = args.board;
    let (path, bytes) = write(&elf, board, "uf2")?;
    println!("{}", describe(&path, board, &bytes));
    println!(
        "To flash it: unplug the {name}, hold its BOOTSEL button while you plug it in, and let \
         go; a USB drive called {label} appears. Copy {uf2} onto that drive. The board restarts \
         and runs the new firmware as soon as the copy is complete.",
        name = board.name(),
        label = board.drive_label(),
        uf2 = project::relative(&path).display()
    );
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_image_the_boot_rom_would_not_start_is_refused() {
        // This test binary: an ELF, but for no board.
        let host = std::fs::read(std::env::current_exe().unwrap()).unwrap();
        let error = format!("{:#}", make(&host, Board::Pico).unwrap_err());
        assert!(error.contains("no `.boot2` section"), "{error}");
        let error = format!("{:#}", make(&host, Board::Pico2).unwrap_err());
        assert!(error.contains("no `.start_block` section"), "{error}");
    }
}
