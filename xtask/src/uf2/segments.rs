//! The bytes an ELF puts in flash ([`elf::segments`](crate::elf::segments):
//! its loadable segments' contents at their load addresses), checked
//! against the board's flash before a UF2 is written.

use object::read::elf::ElfFile32;
use object::{Endianness, elf};

use super::problem::Problem;
use crate::board::Board;
use crate::elf::Segment;

/// The loadable segments with contents of the ELF `file`, in address
/// order, checked for `board`: inside its flash, clear of its settings,
/// none overlapping another.
///
/// # Errors
/// A [`Problem`] for anything else: the UF2 would not be the image the
/// board must run, or the writer could not make one.
pub fn read(file: &[u8], board: Board) -> Result<Vec<Segment>, Problem> {
    let elf =
        ElfFile32::<Endianness>::parse(file).map_err(|error| Problem::NotElf(error.to_string()))?;
    let endian = elf.endian();
    if endian != Endianness::Little || elf.elf_header().e_machine.get(endian) != elf::EM_ARM {
        return Err(Problem::NotElf("not little-endian Arm".to_owned()));
    }
    let segments = crate::elf::segments(&elf).map_err(|error| Problem::NotElf(error.to_owned()))?;
    if segments.is_empty() {
        return Err(Problem::NoContents);
    }

    let flash = board.flash();
    let settings = board.settings();
    for segment in &segments {
        let range = segment.range();
        if range.start < flash.start || range.end > flash.end {
            return Err(Problem::OutsideFlash {
                segment: range,
                flash,
            });
        }
        if range.end > settings.start {
            return Err(Problem::InSettings {
                segment: range,
                settings,
            });
        }
    }
    for pair in segments.windows(2) {
        let (first, second) = (pair[0].range(), pair[1].range());
        if second.start < first.end {
            return Err(Problem::Overlap { first, second });
        }
    }
    Ok(segments)
}
