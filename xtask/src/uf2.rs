//! `cargo xtask uf2`: the firmware as a UF2 file, which a board in BOOTSEL
//! mode flashes itself when it is copied onto the USB drive it shows.
//!
//! The blocks are written by the `elf2flash-core` crate, a port of the
//! Raspberry Pi SDK's `elf2uf2`: the loadable segments' contents at their
//! load addresses, one 256-byte flash page per block, and every page of a
//! 4 KiB erase sector the image touches present (zeros where the image has
//! none), as the RP2040 boot ROM needs: it erases a sector when a block's
//! *number* says a new sector begins, so a partly filled sector before the
//! last would be erased under pages already written (RP2040 erratum E14).
//!
//! Before it is written, every file is read back (`format.rs`, from the
//! specification) and compared with the ELF: the board's family in every
//! block, blocks contiguous from the start of flash, clear of the settings
//! sectors, and every byte the ELF's.

mod format;
mod problem;
mod segments;
mod sizes;
#[cfg(test)]
mod test_elf;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use elf2flash_core::boards::{BoardInfo, RP2040, RP2350};

pub use self::format::Layout;
use crate::{board::Board, elf, project, rp2350, setup};

/// `cargo xtask uf2`.
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

/// A UF2 file made and checked.
#[derive(Debug)]
pub struct Uf2 {
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// What it holds.
    pub layout: Layout,
}

/// The UF2 of the ELF `elf` for `board`, read back and checked against it.
///
/// # Errors
/// If the ELF is not an image for the board's flash (see
/// `segments::read`), the writer fails, the file it wrote is not the ELF's
/// image (see `format::check`), or the board's boot ROM would not start it
/// (see [`check_boot`]).
pub fn make(elf: &[u8], board: Board) -> Result<Uf2> {
    let segments = segments::read(elf, board)?;
    let chip: &dyn BoardInfo = match board {
        Board::Pico => &RP2040,
        Board::Pico2 => &RP2350,
    };
    let mut bytes = Vec::new();
    elf2flash_core::elf2uf2(elf, &mut bytes, chip, elf2flash_core::NoProgress)
        .context("writing the UF2 blocks")?;
    let blocks = format::parse(&bytes).context("reading the UF2 back")?;
    let layout = format::check(&blocks, board, &segments)
        .context("comparing the UF2 with the ELF's loadable segments")?;
    check_boot(elf, board)?;
    Ok(Uf2 { bytes, layout })
}

/// Fails unless the ELF has what the board's boot ROM starts an image
/// from: on the Pico, the 256-byte second stage (`.boot2`) at the start of
/// flash; on the Pico 2, a block in its first 4 KiB (`.start_block`).
///
/// # Errors
/// If it has not: a board would stay in BOOTSEL mode after the copy.
pub fn check_boot(data: &[u8], board: Board) -> Result<()> {
    match board {
        Board::Pico => elf::Image::parse(data)
            .context("parsing the ELF")?
            .check_boot2(),
        Board::Pico2 => rp2350::start_block(data).map(|_| ()),
    }
}

/// Where the UF2 of `elf` goes: beside it, `.uf2` for an extension
/// (`…/release/pico` → `…/release/pico.uf2`).
pub fn path_for(elf: &Path) -> PathBuf {
    elf.with_extension("uf2")
}

/// Makes the UF2 of the ELF at `elf` and writes it beside it; returns its
/// path and contents.
///
/// # Errors
/// If the ELF cannot be read, [`make`] fails, or the file cannot be written.
pub fn write(elf: &Path, board: Board) -> Result<(PathBuf, Uf2)> {
    let data = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let uf2 = make(&data, board).with_context(|| format!("the UF2 of {}", elf.display()))?;
    let path = path_for(elf);
    std::fs::write(&path, &uf2.bytes).with_context(|| format!("writing {}", path.display()))?;
    Ok((path, uf2))
}

/// One line about a UF2 written to `path`.
pub fn describe(path: &Path, board: Board, layout: &Layout) -> String {
    format!(
        "{}: {} blocks of 256 B, flash {:#010x}..{:#010x} ({} B of the ELF's segments), \
         family {:#010x} for the {}",
        project::relative(path).display(),
        layout.blocks,
        layout.flash.start,
        layout.flash.end,
        layout.loaded,
        layout.family,
        board.name()
    )
}

/// How to flash the UF2 at `path` onto `board` through its BOOTSEL drive.
pub fn bootsel_steps(path: &Path, board: Board) -> String {
    format!(
        "To flash it: unplug the {name}, hold its BOOTSEL button while you plug it in, and let \
         go; a USB drive called {label} appears. Copy {uf2} onto that drive. The board restarts \
         and runs the new firmware as soon as the copy is complete.",
        name = board.name(),
        label = board.drive_label(),
        uf2 = project::relative(path).display()
    )
}

/// `cargo xtask uf2`: builds the board's image unless an ELF is given,
/// writes its UF2 beside it and says how to flash it.
///
/// # Errors
/// If the build fails or the UF2 cannot be made (see [`write`]).
pub fn command(args: &Args) -> Result<bool> {
    let elf = if let Some(elf) = &args.elf {
        elf.clone()
    } else {
        let root = project::root();
        setup::ensure_toolchain(&root)?;
        args.board.build()?;
        args.board.elf(&project::metadata(&root)?)
    };
    let (path, uf2) = write(&elf, args.board)?;
    println!("{}", describe(&path, args.board, &uf2.layout));
    println!("{}", bootsel_steps(&path, args.board));
    Ok(true)
}

/// The name of the stage of `cargo xtask test` that makes the Pico image's UF2.
pub const PICO_STAGE: &str =
    "Pico UF2 (cargo xtask uf2): read back, blocks = the ELF's flash, family RP2040";

/// The stage [`PICO_STAGE`]: the UF2 of the Pico image already built.
///
/// # Errors
/// If the UF2 cannot be made or is not the ELF's image.
pub fn test_pico(metadata: &project::Metadata) -> Result<()> {
    let board = Board::Pico;
    let (path, uf2) = write(&board.elf(metadata), board)?;
    println!("{}", describe(&path, board, &uf2.layout));
    Ok(())
}

/// A small image that both boards would start: a `.boot2` for the Pico, a
/// start block for the Pico 2, and some code.
#[cfg(test)]
pub fn sample_elf() -> Vec<u8> {
    use test_elf::{Load, build, pattern, start_block};
    build(&[
        Load::flash(0x1000_0000, pattern(0, 256)).section(".boot2"),
        Load::flash(0x1000_0100, start_block()).section(".start_block"),
        Load::flash(0x1000_0114, pattern(9, 700)),
    ])
}

#[cfg(test)]
mod tests {
    use super::format::{self, BLOCK_SIZE};
    use super::problem::Problem;
    use super::test_elf::{Load, build, pattern};
    use super::*;

    /// Where a field of block `block` lies in the file.
    fn at(block: usize, word: usize) -> usize {
        block * BLOCK_SIZE + 4 * word
    }

    /// A Pico-like image: a 256-byte boot stage, code from the next page,
    /// and initialised data stored after the code but run in RAM.
    fn pico_like() -> (Vec<u8>, Vec<Load>) {
        let loads = vec![
            Load::flash(0x1000_0000, pattern(1, 256)).section(".boot2"),
            Load::flash(0x1000_0100, pattern(7, 5000)),
            Load {
                run: 0x2000_0000,
                stored: 0x1000_0100 + 5000,
                data: pattern(99, 300),
                memory: 300,
                section: None,
            },
            // `.bss`: memory, no contents.
            Load {
                run: 0x2000_012c,
                stored: 0x2000_012c,
                data: Vec::new(),
                memory: 4000,
                section: None,
            },
        ];
        (build(&loads), loads)
    }

    fn problem(result: Result<Uf2>) -> Problem {
        result
            .unwrap_err()
            .downcast_ref::<Problem>()
            .cloned()
            .expect("a Problem")
    }

    #[test]
    fn a_pico_image_becomes_whole_pages_from_the_start_of_flash() {
        let (elf, loads) = pico_like();
        let uf2 = make(&elf, Board::Pico).unwrap();
        // 256 + 5000 + 300 bytes stored: 5556 B → 22 pages, up to 0x100015b4.
        assert_eq!(uf2.layout.blocks, 22);
        assert_eq!(uf2.layout.flash, 0x1000_0000..0x1000_1600);
        assert_eq!(uf2.layout.loaded, 5556);
        assert_eq!(uf2.bytes.len(), 22 * BLOCK_SIZE);

        // Read back by hand, field by field.
        let word = |at: usize| u32::from_le_bytes(uf2.bytes[at..at + 4].try_into().unwrap());
        for block in 0..22_u32 {
            let at = |word| at(block as usize, word);
            assert_eq!(word(at(0)), 0x0a32_4655);
            assert_eq!(word(at(1)), 0x9e5d_5157);
            assert_eq!(word(at(2)), 0x2000, "flags: family ID present");
            assert_eq!(word(at(3)), 0x1000_0000 + 256 * block);
            assert_eq!(word(at(4)), 256);
            assert_eq!(word(at(5)), block);
            assert_eq!(word(at(6)), 22);
            assert_eq!(word(at(7)), 0xe48b_ff56, "RP2040");
            assert_eq!(word(at(127)), 0x0ab1_6f30);
        }
        // The data stored after the code: in flash at its load address.
        let data = 0x1000_0100 + 5000 - 0x1000_0000;
        let (block, offset) = (data / 256, data % 256);
        let first = block * BLOCK_SIZE + 32 + offset;
        assert_eq!(uf2.bytes[first..first + 4], loads[2].data[..4]);
    }

    #[test]
    fn a_pico_2_image_is_of_the_rp2350_arm_secure_family() {
        let elf = sample_elf();
        let uf2 = make(&elf, Board::Pico2).unwrap();
        assert_eq!(uf2.layout.family, 0xe48b_ff59);
        // 0x114 + 700 B = 976 B: 4 pages.
        assert_eq!(uf2.layout.blocks, 4);
        let blocks = format::parse(&uf2.bytes).unwrap();
        assert!(blocks.iter().all(|block| block.family == 0xe48b_ff59));
        // The same ELF is no Pico image: its blocks are for another chip.
        let pico_blocks = format::parse(&make(&elf, Board::Pico).unwrap().bytes).unwrap();
        let segments = segments::read(&elf, Board::Pico2).unwrap();
        assert_eq!(
            format::check(&pico_blocks, Board::Pico2, &segments),
            Err(Problem::Family {
                block: 0,
                found: 0xe48b_ff56,
                expected: 0xe48b_ff59
            })
        );
    }

    #[test]
    fn a_hole_between_segments_is_zero_filled_up_to_the_sector() {
        // Code in the first page, constants from the third: the second
        // page is in no segment, but in the same erase sector.
        let elf = build(&[
            Load::flash(0x1000_0000, pattern(1, 256)).section(".boot2"),
            Load::flash(0x1000_0200, pattern(5, 100)),
        ]);
        let uf2 = make(&elf, Board::Pico).unwrap();
        assert_eq!(uf2.layout.blocks, 3);
        let blocks = format::parse(&uf2.bytes).unwrap();
        assert!(blocks[1].payload.iter().all(|&b| b == 0));
        assert_eq!(blocks[2].payload[..100], pattern(5, 100)[..]);
        assert!(blocks[2].payload[100..].iter().all(|&b| b == 0));
    }

    #[test]
    fn a_changed_byte_family_or_order_is_caught() {
        let (elf, _) = pico_like();
        let good = make(&elf, Board::Pico).unwrap().bytes;
        let segments = segments::read(&elf, Board::Pico).unwrap();
        let check = |bytes: &[u8]| {
            format::parse(bytes).and_then(|blocks| format::check(&blocks, Board::Pico, &segments))
        };
        assert!(check(&good).is_ok());

        let mut byte = good.clone();
        byte[3 * BLOCK_SIZE + 32 + 10] ^= 0x40;
        assert_eq!(
            check(&byte),
            Err(Problem::Bytes {
                address: 0x1000_0300 + 10,
                found: pattern(7, 5000)[0x200 + 10] ^ 0x40,
                expected: pattern(7, 5000)[0x200 + 10],
            })
        );

        let mut family = good.clone();
        family[at(5, 7)..at(5, 8)].copy_from_slice(&0xe48b_ff59_u32.to_le_bytes());
        assert!(matches!(
            check(&family),
            Err(Problem::Family { block: 5, .. })
        ));

        // Blocks 1 and 2 swapped, numbers and all.
        let mut swapped = good.clone();
        let (one, two) = (BLOCK_SIZE, 2 * BLOCK_SIZE);
        let block_one = swapped[one..two].to_vec();
        swapped.copy_within(two..two + BLOCK_SIZE, one);
        swapped[two..two + BLOCK_SIZE].copy_from_slice(&block_one);
        assert!(matches!(
            check(&swapped),
            Err(Problem::Numbering { block: 1, found: 2 })
        ));

        let mut magic = good.clone();
        magic[at(4, 127)] ^= 1;
        assert_eq!(check(&magic), Err(Problem::Magic { block: 4 }));

        assert_eq!(
            check(&good[..good.len() - 1]),
            Err(Problem::Length(good.len() - 1))
        );
        assert_eq!(check(&[]), Err(Problem::Length(0)));

        // The last block dropped: the file is whole but says 22 blocks.
        assert!(matches!(
            check(&good[..good.len() - BLOCK_SIZE]),
            Err(Problem::Total {
                found: 22,
                expected: 21,
                ..
            })
        ));
    }

    #[test]
    fn images_not_for_the_boards_flash_are_refused() {
        let ram = build(&[Load::flash(0x2000_0000, pattern(0, 64))]);
        assert!(matches!(
            problem(make(&ram, Board::Pico)),
            Problem::OutsideFlash { .. }
        ));
        // 3 MiB in: on the Pico 2's flash, past the Pico's.
        let high = build(&[
            Load::flash(0x1000_0000, pattern(0, 64)),
            Load::flash(0x1030_0000, pattern(0, 64)),
        ]);
        assert!(matches!(
            problem(make(&high, Board::Pico)),
            Problem::OutsideFlash { .. }
        ));
        let settings = build(&[Load::flash(0x101f_bff0, pattern(0, 64))]);
        assert_eq!(
            problem(make(&settings, Board::Pico)),
            Problem::InSettings {
                segment: 0x101f_bff0..0x101f_c030,
                settings: 0x101f_c000..0x1020_0000
            }
        );
        let overlap = build(&[
            Load::flash(0x1000_0000, pattern(0, 512)),
            Load::flash(0x1000_0100, pattern(0, 64)),
        ]);
        assert!(matches!(
            problem(make(&overlap, Board::Pico)),
            Problem::Overlap { .. }
        ));
        let empty = build(&[Load {
            run: 0x2000_0000,
            stored: 0x2000_0000,
            data: Vec::new(),
            memory: 64,
            section: None,
        }]);
        assert_eq!(problem(make(&empty, Board::Pico)), Problem::NoContents);
        assert!(matches!(
            problem(make(b"not an elf", Board::Pico)),
            Problem::NotElf(_)
        ));
    }

    #[test]
    fn an_image_must_start_at_the_start_of_flash() {
        let late = build(&[Load::flash(0x1000_1000, pattern(0, 64))]);
        assert_eq!(
            problem(make(&late, Board::Pico)),
            Problem::Start {
                address: 0x1000_1000,
                expected: 0x1000_0000
            }
        );
    }

    #[test]
    fn an_image_the_boot_rom_would_not_start_is_refused() {
        let code = || Load::flash(0x1000_0100, pattern(0, 300));
        let without = build(&[Load::flash(0x1000_0000, pattern(0, 256)), code()]);
        let error = format!("{:#}", make(&without, Board::Pico).unwrap_err());
        assert!(error.contains("`.boot2`"), "{error}");
        let short = build(&[
            Load::flash(0x1000_0000, pattern(0, 252)).section(".boot2"),
            code(),
        ]);
        assert!(make(&short, Board::Pico).is_err());

        let error = format!("{:#}", make(&without, Board::Pico2).unwrap_err());
        assert!(error.contains("no `.start_block`"), "{error}");
        let mut broken = test_elf::start_block();
        broken[16] ^= 1;
        let unmarked = build(&[
            Load::flash(0x1000_0000, pattern(0, 256)),
            Load::flash(0x1000_0100, broken).section(".start_block"),
        ]);
        let error = format!("{:#}", make(&unmarked, Board::Pico2).unwrap_err());
        assert!(error.contains("not a block"), "{error}");
        let late = build(&[
            Load::flash(0x1000_0000, pattern(0, 0x1000)),
            Load::flash(0x1000_1000, test_elf::start_block()).section(".start_block"),
        ]);
        let error = format!("{:#}", make(&late, Board::Pico2).unwrap_err());
        assert!(error.contains("outside the first 4 KiB"), "{error}");
    }

    #[test]
    fn the_uf2_goes_beside_the_elf() {
        assert_eq!(
            path_for(Path::new("target/thumbv6m-none-eabi/release/pico")),
            Path::new("target/thumbv6m-none-eabi/release/pico.uf2")
        );
        let dir = tempfile::tempdir().unwrap();
        let elf = dir.path().join("pico2");
        std::fs::write(&elf, sample_elf()).unwrap();
        let (path, uf2) = write(&elf, Board::Pico2).unwrap();
        assert_eq!(path, dir.path().join("pico2.uf2"));
        assert_eq!(std::fs::read(&path).unwrap(), uf2.bytes);
    }
}
