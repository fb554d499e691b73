//! The boards a user flashes: their images, UF2 families and drives.

use std::ops::Range;

use elf2flash_core::boards::{BoardInfo, RP2040, RP2350};
use idle_head_core::console::BoardParts;
use idle_head_core::input::InputIds;

use crate::project::{Image, PICO};

/// The Pico's trigger inputs, as `crates/rp/src/pico.rs` wires them: GP2
/// to GP5, `input 2` to `input 5`.
pub const PICO_INPUTS: [u8; 4] = [2, 3, 4, 5];

/// What the Pico image's console answers for (`crates/rp/src/pico.rs`).
pub fn pico_parts() -> BoardParts {
    BoardParts {
        inputs: InputIds::new(&PICO_INPUTS).unwrap_or(InputIds::NONE),
        dmx: true,
        radar: true,
    }
}

/// The Pico 2's compilation target: the RP2350's Cortex-M33 (ARMv8-M
/// Mainline, with its single-precision FPU).
pub const PICO2_TARGET: &str = "thumbv8m.main-none-eabihf";

/// A board that takes a UF2 file over USB, or a debug probe.
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

    /// Its release image (`cargo build --release` in its package's folder).
    pub fn image(self) -> Image {
        match self {
            Self::Pico => PICO,
            Self::Pico2 => Image {
                bin: "pico2",
                dir: "boards/pico2",
                target: PICO2_TARGET,
                package: None,
            },
        }
    }

    /// Its chip for elf2flash, whose UF2 family its boot ROM accepts:
    /// `rp2040`, or `rp2350-arm-s` (Arm Secure, as embassy-rp's start block
    /// declares).
    pub fn uf2_chip(self) -> &'static dyn BoardInfo {
        match self {
            Self::Pico => &RP2040,
            Self::Pico2 => &RP2350,
        }
    }

    /// The chip's name for `probe-rs run --chip`.
    pub fn probe_rs_chip(self) -> &'static str {
        match self {
            Self::Pico => "RP2040",
            Self::Pico2 => "RP235x",
        }
    }

    /// The `Board-ID` in `INFO_UF2.TXT` on its BOOTSEL drive, also the
    /// drive's label.
    pub fn drive_label(self) -> &'static str {
        match self {
            Self::Pico => "RPI-RP2",
            Self::Pico2 => "RP2350",
        }
    }

    /// The settings store: the last four 4 KiB sectors of the flash
    /// (`SETTINGS` in the board's memory.x).
    pub fn settings(self) -> Range<u64> {
        let end = 0x1000_0000
            + match self {
                Self::Pico => 2 << 20,
                Self::Pico2 => 4 << 20,
            };
        end - 16 * 1024..end
    }
}
