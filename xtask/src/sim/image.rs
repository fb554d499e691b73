//! The Pico image as the harness runs it: its wiring, the symbols it needs
//! from the ELF (the flash comes from its UF2), the base configuration.

use std::path::Path;

use anyhow::{Context, Result, bail};
use object::read::elf::ElfFile32;
use object::{Endianness, Object, ObjectSymbol, elf};

use super::node::Config;
use crate::{board::Board, elf::XIP, uf2};

/// Where boot2 leaves the vector table: right behind its own 256 bytes.
pub const VECTOR_TABLE: u64 = XIP.start + 0x100;

/// The servos on the Pico (`crates/rp/src/pico.rs`): name, GPIO, slice.
pub const SERVOS: [(&str, u8, u8); 3] = [("pitch", 16, 0), ("roll", 18, 1), ("yaw", 20, 2)];

/// The parts of a Pico ELF the emulator run uses.
#[derive(Debug)]
pub struct PicoImage {
    /// Address of the RTT control block `_SEGGER_RTT`.
    pub rtt: u64,
    /// The stack region `[_stack_end, _stack_start)`.
    pub stack: (u64, u64),
    /// Entry of the frame update `FrameLoop::write`, if it is a function of
    /// its own (it is `#[inline(never)]`).
    pub frame_update: Option<u64>,
}

impl PicoImage {
    /// Reads `path`; a file that is not a Pico image gets an error saying why.
    pub fn read(path: &Path) -> Result<Self> {
        let data = std::fs::read(path).with_context(|| {
            let path = path.display();
            format!("the Pico ELF {path} is missing (build it with `cargo build --release`)")
        })?;
        Self::parse(&data).with_context(|| format!("{} is not a Pico image", path.display()))
    }

    fn parse(data: &[u8]) -> Result<Self> {
        let file = ElfFile32::<Endianness>::parse(data)
            .context("not a 32-bit ELF file (the Pico image is a thumbv6m-none-eabi ELF)")?;
        if file.elf_header().e_machine.get(file.endian()) != elf::EM_ARM {
            bail!("not an Arm ELF file");
        }
        if file.section_by_name(".boot2").is_none() {
            bail!("no `.boot2` section (an image for another board?)");
        }
        let symbol = |name| file.symbol_by_name(name).map(|s| s.address());
        let rtt =
            symbol("_SEGGER_RTT").context("no `_SEGGER_RTT` symbol: the image has no RTT log")?;
        let stack = (
            symbol("_stack_end").context("no `_stack_end` symbol")?,
            symbol("_stack_start").context("no `_stack_start` symbol")?,
        );
        let frame_update = (file.symbols())
            .filter(|symbol| symbol.kind() == object::SymbolKind::Text)
            .find(|symbol| {
                symbol.name().is_ok_and(|name| {
                    let name = format!("{:#}", rustc_demangle::demangle(name));
                    name.contains("FrameLoop") && name.ends_with("::write")
                })
            })
            // Thumb: the low bit of a function symbol is the mode bit.
            .map(|symbol| symbol.address() & !1);
        Ok(Self {
            rtt,
            stack,
            frame_update,
        })
    }
}

/// The image `elf` and the harness's configuration for it: its UF2
/// (written to `<elf>.<extension>`), vector table, RTT, servo slices.
pub fn config(elf: &Path, extension: &str) -> Result<(PicoImage, Config)> {
    let image = PicoImage::read(elf)?;
    let (flash, _) = uf2::write(elf, Board::Pico, extension)?;
    let config = Config {
        flash,
        vtor: VECTOR_TABLE,
        rtt: image.rtt,
        slices: SERVOS.iter().map(|s| s.2).collect(),
        ..Config::default()
    };
    Ok((image, config))
}
