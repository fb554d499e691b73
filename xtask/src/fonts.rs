//! The one font of the PNG plots (`preview`, `trace`): `DejaVu Sans`, built
//! in, so that a plot looks the same on every machine.

use std::sync::Once;

use anyhow::{Result, anyhow};
use plotters::style::{FontStyle, register_font};

/// The family name the plots ask for.
pub const FONT: &str = "sans-serif";

/// Registers `DejaVu Sans` (regular and bold) as [`FONT`], once per process.
pub fn register() -> Result<()> {
    static ONCE: Once = Once::new();
    let mut result = Ok(());
    ONCE.call_once(|| {
        for (style, bytes) in [
            (FontStyle::Normal, dejavu::sans::regular()),
            (FontStyle::Bold, dejavu::sans::bold()),
        ] {
            if register_font(FONT, style, bytes).is_err() {
                result = Err(anyhow!("the DejaVu Sans font did not load"));
            }
        }
    });
    result
}
