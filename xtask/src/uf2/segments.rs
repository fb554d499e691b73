//! The bytes an ELF puts in flash: its loadable segments' contents at their
//! load (physical) addresses, so that `.data`'s initial values count where
//! they are stored, not where they run.

use std::ops::Range;

use object::read::elf::{ElfFile32, ProgramHeader};
use object::{Endianness, elf};

use super::problem::Problem;
use crate::board::Board;

/// The contents of one loadable segment.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Segment {
    /// Load address of the first byte.
    pub address: u32,
    /// The bytes stored in the file (`p_filesz` of them).
    pub data: Vec<u8>,
}

impl Segment {
    /// Load addresses of the contents.
    pub fn range(&self) -> Range<u32> {
        // The length fits: `read` took it from a 32-bit field and checked
        // that the end does not wrap.
        let length = u32::try_from(self.data.len()).unwrap_or(u32::MAX);
        self.address..self.address.saturating_add(length)
    }
}

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
    let mut segments = Vec::new();
    for header in elf.elf_program_headers() {
        if header.p_type(endian) != elf::PT_LOAD || header.p_filesz(endian) == 0 {
            continue;
        }
        let data = header
            .data(endian, file)
            .map_err(|()| Problem::NotElf("a segment lies past the end of the file".to_owned()))?;
        let address = header.p_paddr(endian);
        if address.checked_add(header.p_filesz(endian)).is_none() {
            return Err(Problem::NotElf(
                "a segment wraps the address space".to_owned(),
            ));
        }
        segments.push(Segment {
            address,
            data: data.to_vec(),
        });
    }
    if segments.is_empty() {
        return Err(Problem::NoContents);
    }
    segments.sort_by_key(|segment| segment.address);

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
