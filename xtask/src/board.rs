//! The boards a user flashes: what the tools need to know to build an
//! image for each, turn it into a UF2 and put it on the board.

use std::{ops::Range, path::PathBuf};

use anyhow::Result;
use xshell::cmd;

use crate::project::{self, FIRMWARE_ENV, Metadata};

/// UF2 family of the RP2040 (`RP2040_FAMILY_ID` of the UF2 specification's
/// family list, `rp2040` in picotool): its boot ROM ignores blocks of any
/// other family.
pub const RP2040_FAMILY_ID: u32 = 0xe48b_ff56;
/// UF2 family of an RP2350 image for its Arm cores in Secure mode
/// (`RP2350_ARM_S_FAMILY_ID`, `rp2350-arm-s` in picotool), the mode
/// embassy-rp's start block declares.
pub const RP2350_ARM_S_FAMILY_ID: u32 = 0xe48b_ff59;

/// The Pico 2's compilation target: the RP2350's Cortex-M33 (ARMv8-M
/// Mainline, with its single-precision FPU).
pub const PICO2_TARGET: &str = "thumbv8m.main-none-eabihf";

/// A board whose boot ROM takes a UF2 file over USB and that a debug probe
/// can flash.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Board {
    /// Raspberry Pi Pico (RP2040, 2 MiB flash): the root package.
    Pico,
    /// Raspberry Pi Pico 2 (RP2350A, 4 MiB flash): boards/pico2/.
    Pico2,
}

impl Board {
    /// The board's name for people.
    pub fn name(self) -> &'static str {
        match self {
            Self::Pico => "Pico (RP2040)",
            Self::Pico2 => "Pico 2 (RP2350)",
        }
    }

    /// Its compilation target.
    pub fn target(self) -> &'static str {
        match self {
            Self::Pico => project::TARGET,
            Self::Pico2 => PICO2_TARGET,
        }
    }

    /// Its image's bin name, also the ELF's file name.
    pub fn bin(self) -> &'static str {
        match self {
            Self::Pico => "pico",
            Self::Pico2 => "pico2",
        }
    }

    /// The folder of its package, relative to the repository root, where
    /// `cargo build --release` builds its image.
    pub fn package_dir(self) -> &'static str {
        match self {
            Self::Pico => ".",
            Self::Pico2 => "boards/pico2",
        }
    }

    /// The family its boot ROM accepts in a UF2 block.
    pub fn family_id(self) -> u32 {
        match self {
            Self::Pico => RP2040_FAMILY_ID,
            Self::Pico2 => RP2350_ARM_S_FAMILY_ID,
        }
    }

    /// The chip's name for `probe-rs run --chip`.
    pub fn probe_rs_chip(self) -> &'static str {
        match self {
            Self::Pico => "RP2040",
            Self::Pico2 => "RP235x",
        }
    }

    /// The `Board-ID` its boot ROM writes in `INFO_UF2.TXT` on the USB
    /// drive of BOOTSEL mode, which is also the drive's label.
    pub fn drive_label(self) -> &'static str {
        match self {
            Self::Pico => "RPI-RP2",
            Self::Pico2 => "RP2350",
        }
    }

    /// Where its flash appears (execute-in-place window), as far as the
    /// chip on the board reaches: 2 MiB on the Pico, 4 MiB on the Pico 2.
    pub fn flash(self) -> Range<u32> {
        const XIP_BASE: u32 = 0x1000_0000;
        match self {
            Self::Pico => XIP_BASE..XIP_BASE + (2 << 20),
            Self::Pico2 => XIP_BASE..XIP_BASE + (4 << 20),
        }
    }

    /// The settings store: the last four 4 KiB erase sectors of the flash
    /// (`SETTINGS` in the board's memory.x). No image reaches into it.
    pub fn settings(self) -> Range<u32> {
        let end = self.flash().end;
        end - 16 * 1024..end
    }

    /// The release ELF of its image.
    pub fn elf(self, metadata: &Metadata) -> PathBuf {
        metadata
            .target_dir
            .join(self.target())
            .join("release")
            .join(self.bin())
    }

    /// `cargo build --release` in the board's package folder, as a user
    /// types it there (the folder's `.cargo/config.toml` picks the target).
    pub fn build(self) -> Result<()> {
        let sh = project::shell(self.package_dir())?;
        project::run(&sh, FIRMWARE_ENV, cmd!(sh, "cargo build --release"))
    }
}
