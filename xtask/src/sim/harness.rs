//! The Pico as the emulator's harness (`sim/harness.mjs`) runs it: where
//! its servos and trigger inputs are wired, and the configuration every run
//! of its image starts from.

use std::path::Path;

use anyhow::Result;
use idle_head_core::input::{FIRST_INPUT, INPUTS};

use super::image::{PicoImage, VECTOR_TABLE};
use super::node;

/// The servos as wired on the Pico (`crates/rp/src/pico.rs`): name, GPIO,
/// PWM slice (channel A).
pub const SERVOS: [(&str, u8, u8); 3] = [("pitch", 16, 0), ("roll", 18, 1), ("yaw", 20, 2)];

/// The trigger inputs' GPIOs, as wired on the Pico: GP2 to GP5.
pub fn input_pins() -> Vec<u8> {
    (FIRST_INPUT..).take(INPUTS).collect()
}

/// The harness's configuration for the Pico image `elf`, and the image:
/// its UF2 written beside it (`<elf>.<extension>`, `cargo xtask uf2`'s
/// file), its vector table and RTT log, the servo slices' compare writes
/// reported.
pub fn config(elf: &Path, extension: &str) -> Result<(PicoImage, node::Config)> {
    let image = PicoImage::read(elf)?;
    let (flash, _) = crate::uf2::write(elf, crate::board::Board::Pico, extension)?;
    let config = node::Config {
        flash,
        vtor: VECTOR_TABLE,
        rtt: image.rtt,
        slices: SERVOS.iter().map(|s| s.2).collect(),
        ..node::Config::default()
    };
    Ok((image, config))
}
