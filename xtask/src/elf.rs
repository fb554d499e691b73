//! Reads a firmware ELF: section placement and sizes, memory budgets, and
//! symbols that must not be linked.

use std::{ops::Range, path::Path};

use anyhow::{Context, Result, bail, ensure};

use crate::{board::Board, figures, project};
use object::SectionKind::{UninitializedData, UninitializedTls};
use object::read::elf::{ElfFile32, ProgramHeader};
use object::{Endianness, Object, ObjectSection, ObjectSymbol, SectionFlags, elf};

/// RAM budget of the Pico image (of the RP2040's 264 KiB): static RAM plus
/// the peak stack measured in the RP2040 emulator, deepest in the settings
/// store's run (a saved record read back under both executors).
pub const RAM_BUDGET: u64 = 50 * 1024;
/// Flash budget of the Pico image: every section stored in flash.
pub const FLASH_BUDGET: u64 = 192 * 1024;
/// The RP2040's XIP flash window (16 MiB at most).
pub const XIP: Range<u64> = 0x1000_0000..0x1100_0000;

/// Parts of the names of symbols linked only with an allocator (matched by
/// substring: recent compilers mangle the shims).
const ALLOCATOR_SYMBOLS: &[&str] = &[
    "__rust_alloc",
    "__rust_realloc",
    "__rust_dealloc",
    "__rg_alloc",
    "__rdl_alloc",
];

/// One allocated section of the image.
#[derive(Debug, Clone)]
pub struct Section {
    pub name: String,
    pub address: u64,
    pub size: u64,
    /// Has contents in the file, and so in flash (not `.bss`, `.uninit`).
    pub stored: bool,
}

/// What the checks need to know about a firmware ELF.
#[derive(Debug, Default)]
pub struct Image {
    /// Allocated sections in address order.
    pub sections: Vec<Section>,
    /// Allocator symbols found (there should be none).
    pub allocator_symbols: Vec<String>,
    /// `[__settings_start, __settings_end)` from memory.x, if present.
    pub settings: Option<Range<u64>>,
    /// End of the bytes stored in the XIP window: the highest load address
    /// of a segment there (so `.data`'s initial values count).
    pub flash_end: u64,
}

impl Image {
    pub fn read(path: &Path) -> Result<Self> {
        let data = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
        Self::parse(&data).with_context(|| format!("parsing {}", path.display()))
    }

    /// [`Image::read`], printing the sections and sizes.
    pub fn show(path: &Path) -> Result<Self> {
        let image = Self::read(path)?;
        println!("{}", path.display());
        println!("  {:<16} {:>10}  {:>7}", "section", "address", "bytes");
        for s in &image.sections {
            println!("  {:<16} {:#010x}  {:>7}", s.name, s.address, s.size);
        }
        let (flash, ram) = (image.flash(), image.static_ram());
        println!("  flash {flash} B, static RAM {ram} B (.radar_ring + .data + .bss + .uninit)");
        Ok(image)
    }

    pub fn parse(data: &[u8]) -> Result<Self> {
        let file = object::File::parse(data)?;
        let allocated = |s: &object::Section<'_, '_>| matches!(s.flags(), SectionFlags::Elf { sh_flags } if sh_flags & u64::from(elf::SHF_ALLOC) != 0);
        let mut sections: Vec<Section> = (file.sections())
            .filter(|s| allocated(s) && s.size() > 0)
            .map(|s| Section {
                name: s.name().unwrap_or("?").to_owned(),
                address: s.address(),
                size: s.size(),
                stored: !matches!(s.kind(), UninitializedData | UninitializedTls),
            })
            .collect();
        sections.sort_by_key(|section| section.address);
        let mut allocator_symbols: Vec<String> = (file.symbols())
            .filter_map(|symbol| symbol.name().ok())
            .filter(|name| ALLOCATOR_SYMBOLS.iter().any(|part| name.contains(part)))
            .map(str::to_owned)
            .collect();
        allocator_symbols.sort();
        allocator_symbols.dedup();
        let symbol = |name| file.symbol_by_name(name).map(|s| s.address());
        let settings = symbol("__settings_start")
            .zip(symbol("__settings_end"))
            .map(|(start, end)| start..end);
        // 0 for an ELF that is not a 32-bit one.
        let flash_end = ElfFile32::<Endianness>::parse(data).map_or(0, |file| {
            let e = file.endian();
            (file.elf_program_headers().iter())
                .filter(|h| h.p_type(e) == elf::PT_LOAD && h.p_filesz(e) > 0)
                .filter(|h| XIP.contains(&u64::from(h.p_paddr(e))))
                .map(|h| u64::from(h.p_paddr(e)) + u64::from(h.p_filesz(e)))
                .max()
                .unwrap_or(0)
        });
        Ok(Self {
            sections,
            allocator_symbols,
            settings,
            flash_end,
        })
    }

    /// The section called `name`, if present and non-empty.
    pub fn section(&self, name: &str) -> Option<&Section> {
        self.sections.iter().find(|section| section.name == name)
    }

    /// Bytes of RAM taken before `main` runs.
    pub fn static_ram(&self) -> u64 {
        let ram =
            |s: &&Section| [".radar_ring", ".data", ".bss", ".uninit"].contains(&s.name.as_str());
        self.sections.iter().filter(ram).map(|s| s.size).sum()
    }

    /// Bytes written to flash: every section with contents.
    pub fn flash(&self) -> u64 {
        self.sections
            .iter()
            .filter(|s| s.stored)
            .map(|s| s.size)
            .sum()
    }

    /// Fails unless the vector table is at `address`, where `chip` starts
    /// an image from.
    pub fn check_vector_table(&self, address: u64, chip: &str) -> Result<()> {
        match self.section(".vector_table") {
            Some(table) if table.address == address => Ok(()),
            Some(table) => bail!(
                "`.vector_table` is at {:#010x}; the {chip} starts the image from {address:#010x} \
                 (was the image linked with another board's memory.x?)",
                table.address
            ),
            None => bail!("no `.vector_table` section: the image cannot boot"),
        }
    }

    /// Fails unless the image has the RP2040's second stage: 256 bytes of
    /// `.boot2` at the start of flash, where its boot ROM loads them from.
    pub fn check_boot2(&self) -> Result<()> {
        let hint = "is `-Tlink-rp.x` passed to the linker?";
        match self.section(".boot2") {
            Some(boot2) if boot2.address == XIP.start && boot2.size == 256 => Ok(()),
            Some(boot2) => bail!(
                "`.boot2` is {} bytes at {:#010x}; the RP2040 boot ROM needs 256 bytes at \
                 {:#010x} ({hint})",
                boot2.size,
                boot2.address,
                XIP.start
            ),
            None => bail!("no `.boot2` section: the RP2040 would not boot ({hint})"),
        }
    }

    pub fn check_no_allocator(&self) -> Result<()> {
        ensure!(
            self.allocator_symbols.is_empty(),
            "an allocator is linked (symbols {}); the firmware must not allocate",
            self.allocator_symbols.join(", ")
        );
        Ok(())
    }

    /// Fails unless memory.x reserves `board`'s settings region and nothing
    /// stored in flash reaches into it.
    pub fn check_settings_region(&self, board: Board) -> Result<()> {
        let Some(region) = self.settings.clone() else {
            bail!(
                "no `__settings_start`/`__settings_end` symbols: memory.x must reserve the \
                 settings region"
            );
        };
        let expected = board.settings();
        ensure!(
            region == expected,
            "the settings region is {region:#010x?} in memory.x, but the firmware's store \
             uses {expected:#010x?}"
        );
        let (start, end) = (region.start, self.flash_end);
        ensure!(
            end <= start,
            "the image's flash contents end at {end:#010x}, inside the settings region at \
             {start:#010x}"
        );
        let kib = (region.end - start) / 1024;
        println!(
            "  settings region {region:#010x?} ({kib} KiB) clear: the image ends at {end:#010x}"
        );
        Ok(())
    }
}

pub fn problems(checks: impl IntoIterator<Item = Result<()>>) -> Vec<String> {
    (checks.into_iter())
        .filter_map(|check| check.err().map(|e| format!("{e:#}")))
        .collect()
}

/// Prints the Pico image's sections and budgets; fails on a misplaced
/// `.boot2`, a budget exceeded, an allocator, or the settings region reached.
pub fn check_pico(path: &Path) -> Result<()> {
    let image = Image::show(path)?;
    let (flash, ram) = (image.flash(), image.static_ram());
    record_image(path, &image);
    println!("  budgets: flash {FLASH_BUDGET} B; RAM {RAM_BUDGET} B with the peak stack");
    let mut problems = problems([
        image.check_boot2(),
        image.check_no_allocator(),
        image.check_settings_region(Board::Pico),
    ]);
    for (what, used, budget) in [
        ("flash", flash, FLASH_BUDGET),
        ("static RAM", ram, RAM_BUDGET),
    ] {
        if used > budget {
            problems.push(format!("{what} use {used} B is over the {budget} B budget"));
        }
    }
    project::verdict(&problems)
}

/// Prints the QEMU image's sections (a test image: no budget); fails on a
/// vector table off 0, where the LM3S6965 boots, or an allocator.
pub fn check_qemu(path: &Path) -> Result<()> {
    let image = Image::show(path)?;
    image.check_vector_table(0, "LM3S6965")?;
    image.check_no_allocator()
}

/// Records static RAM and peak stack (if measured) of the Pico and QEMU
/// ELFs; fails if the Pico's is unknown or over [`RAM_BUDGET`].
pub fn check_ram(pico: (&Path, Option<u64>), qemu: (&Path, Option<u64>)) -> Result<()> {
    let measured = |(elf, stack): (&Path, Option<u64>)| -> Result<Option<(u64, u64)>> {
        (stack.map(|stack| Ok((Image::read(elf)?.static_ram(), stack)))).transpose()
    };
    let (pico, qemu) = (measured(pico)?, measured(qemu)?);
    let rows = [
        ("pico", "the RP2040 emulator", pico, Some(RAM_BUDGET)),
        ("qemu", "QEMU (lm3s6965evb)", qemu, None),
    ];
    let rows: Vec<Vec<String>> = (rows.into_iter())
        .filter_map(|(image, measured_in, peak, budget)| {
            let (static_ram, stack) = peak?;
            let total = static_ram + stack;
            Some(vec![
                image.to_owned(),
                measured_in.to_owned(),
                figures::bytes(static_ram),
                figures::bytes(stack),
                format!("{} ({})", figures::bytes(total), figures::kib(total)),
                figures::of_ceiling(total, budget),
            ])
        })
        .collect();
    if !rows.is_empty() {
        let intro = "RAM: static RAM plus the deepest the stack went, measured by painting it \
                     ([Memory](memory.md#how-the-stack-is-measured)).";
        let header = [
            "image",
            "stack measured in",
            "static RAM",
            "peak stack",
            "total",
            "of the ceiling",
        ];
        figures::record("ram", intro.to_owned(), &header, rows);
    }
    let (static_ram, stack) =
        pico.context("the Pico image's peak stack was not measured (the emulator run failed)")?;
    let total = static_ram + stack;
    if total > RAM_BUDGET {
        bail!("RAM use {total} B (static + peak stack) is over the {RAM_BUDGET} B budget");
    }
    println!("  Pico RAM {total} B within the {RAM_BUDGET} B budget");
    Ok(())
}

/// The sizes of the Pico image at `path`, for the measured figures.
fn record_image(path: &Path, image: &Image) {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let flash = image.flash();
    let sections: Vec<String> = (image.sections.iter())
        .map(|s| format!("`{}` {}", s.name, figures::bytes(s.size)))
        .collect();
    let sections = sections.join(", ");
    let intro = format!(
        "Flash is every section stored in flash (`.data`'s initial values included); \
         static RAM is `.radar_ring + .data + .bss + .uninit`. Sections of `{name}`: {sections}."
    );
    let row = vec![
        name.to_string(),
        format!("{} ({})", figures::bytes(flash), figures::kib(flash)),
        figures::of_ceiling(flash, Some(FLASH_BUDGET)),
        figures::bytes(image.static_ram()),
    ];
    let header = ["image", "flash", "of the ceiling", "static RAM"];
    figures::record(&format!("image {name}"), intro, &header, vec![row]);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// This test binary links std, and with it an allocator: the check must see it.
    #[test]
    fn finds_the_allocator_of_a_std_binary() {
        let image = Image::read(&std::env::current_exe().unwrap()).unwrap();
        assert!(image.check_no_allocator().is_err());
        assert!(image.section(".text").is_some_and(|text| text.size > 0));
        assert!(image.flash() > 0);
    }

    #[test]
    fn the_settings_region_must_be_reserved_and_clear() {
        let region = Board::Pico.settings();
        let check = |settings: Option<Range<u64>>, flash_end| {
            let image = Image {
                settings,
                flash_end,
                ..Image::default()
            };
            image
                .check_settings_region(Board::Pico)
                .map_err(|e| format!("{e:#}"))
        };
        assert!(check(Some(region.clone()), 0x1000_c000).is_ok());
        assert!(check(Some(region.clone()), region.start).is_ok());
        let into = check(Some(region.clone()), region.start + 4);
        assert!(into.unwrap_err().contains("inside the settings region"));
        let moved = check(Some(0x1010_0000..0x1010_4000), 0x1000_c000);
        assert!(moved.unwrap_err().contains("the firmware's store uses"));
        let unreserved = check(None, 0x1000_c000);
        assert!(unreserved.unwrap_err().contains("must reserve"));
    }
}
