//! The bounds of a loop's configuration: loop length, walk step and
//! smoothing window. A leaf module: the configuration checks against them
//! and the errors name them.

use crate::units::Angle;

/// Smallest loop length (samples).
pub const MIN_N: usize = 16;
/// Largest loop length (samples); keeps every intermediate sum inside `i32`.
pub const MAX_N: usize = 8192;
/// Largest walk step δ.
pub const MAX_STEP: Angle = Angle::from_degrees(90);
/// Smallest supported window (taps).
pub const MIN_WINDOW: u16 = 3;
/// Largest supported window (taps); bounds the table (4 bytes a tap).
pub const MAX_WINDOW: u16 = 511;
