//! The motion errors: what was rejected, and why, in the user's units.
//!
//! Each error's text is written once, in one table ([`MotionError::text`]):
//! the field it concerns and the rule it broke, with the limits taken from
//! the constants. [`MotionError::message`] joins the two, a static string for
//! logs and compile-time errors; `Display` (and `defmt::Format`) put the
//! rejected value between them and add the limit that applies where it is
//! not a constant:
//!
//! ```text
//! message:      range: outside the axis' anatomical limits (Table 1)
//! AxisError:    yaw range -50°..50°: outside the axis' anatomical limits (Table 1), allowed -23°..32°
//! ```

use core::fmt;

use const_format::{StrWriter, concatcp};

use super::limits::{MAX_N, MAX_STEP, MAX_WINDOW, MIN_N, MIN_WINDOW};
use super::storage::Mdeg16;
use crate::axis::Axis;
use crate::units::{Angle, AngleRange};

/// A rejected motion parameter, handing back what was rejected.
///
/// ```
/// use idle_head_core::motion::MotionError;
/// let e = MotionError::WindowTooSmall { window: 2, min: 3 };
/// assert_eq!(e.message(), "window W: must be at least 3 taps");
/// assert_eq!(e.to_string(), "window W = 2: must be at least 3 taps");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MotionError {
    /// N is below [`MIN_N`].
    LengthTooShort {
        /// The rejected length.
        n: usize,
        /// The smallest allowed.
        min: usize,
    },
    /// N is above [`MAX_N`].
    LengthTooLong {
        /// The rejected length.
        n: usize,
        /// The largest allowed.
        max: usize,
    },
    /// W is below [`MIN_WINDOW`].
    WindowTooSmall {
        /// The rejected window.
        window: u16,
        /// The smallest allowed.
        min: u16,
    },
    /// W is above N/2 (so in particular W ≥ N) or above [`MAX_WINDOW`].
    WindowTooLarge {
        /// The rejected window.
        window: u16,
        /// The largest allowed for this N.
        max: u16,
    },
    /// δ is zero or negative.
    StepNotPositive {
        /// The rejected step.
        step: Angle,
    },
    /// δ is above [`MAX_STEP`].
    StepTooLarge {
        /// The rejected step.
        step: Angle,
        /// The largest allowed.
        max: Angle,
    },
    /// α1 ≥ α2.
    RangeInverted {
        /// The rejected range.
        range: AngleRange,
    },
    /// The range does not contain the neutral pose (0°) strictly inside, so
    /// no loop that starts at zero can fill it.
    RangeExcludesNeutral {
        /// The rejected range.
        range: AngleRange,
    },
    /// The range leaves the axis' anatomical limits (paper, Table 1).
    RangeOutsideLimits {
        /// The axis.
        axis: Axis,
        /// The rejected range.
        range: AngleRange,
        /// The axis' limits.
        limits: AngleRange,
    },
    /// The range does not fit the `i16` millidegree storage
    /// ([`Mdeg16::RANGE`](super::Mdeg16::RANGE), ±32.767°).
    StorageOverflow {
        /// The rejected range.
        range: AngleRange,
    },
    /// The smoothed walk of this seed is (nearly) flat: there is no motion to
    /// scale into the range.
    Degenerate {
        /// The seed.
        seed: u32,
    },
}

/// The parts of an error's text.
#[derive(Clone, Copy)]
struct Text {
    /// The field the error concerns, as the user knows it (`window W`).
    field: &'static str,
    /// The rule it broke (`must be at least 3 taps`).
    rule: &'static str,
    /// `field: rule`.
    message: &'static str,
}

/// A [`Text`] from its field and its rule, the rule's parts joined at
/// compile time (numbers from the constants they name).
macro_rules! text {
    ($field:expr, $($rule:expr),+ $(,)?) => {
        Text {
            field: $field,
            rule: concatcp!($($rule),+),
            message: concatcp!($field, ": ", $($rule),+),
        }
    };
}

const LENGTH: &str = "N (samples per loop)";
const WINDOW: &str = "window W";
const STEP: &str = "step δ";
const RANGE: &str = "range";
const SEED: &str = "seed";

/// [`MAX_STEP`] in whole degrees, for the static message.
const MAX_STEP_DEGREES: i32 = MAX_STEP.millidegrees() / Angle::SCALE;
const _: () = assert!(MAX_STEP.millidegrees() % Angle::SCALE == 0);

/// A value in an error's text, shown in the user's units.
#[derive(Clone, Copy)]
enum Value {
    Count(usize),
    Seed(u32),
    Angle(Angle),
    Range(AngleRange),
    AtMost(u16),
}

impl MotionError {
    /// The error's field and rule: the one table of motion error texts.
    const fn text(&self) -> Text {
        match self {
            Self::LengthTooShort { .. } => text!(LENGTH, "must be at least ", MIN_N),
            Self::LengthTooLong { .. } => text!(LENGTH, "must be at most ", MAX_N),
            Self::WindowTooSmall { .. } => text!(WINDOW, "must be at least ", MIN_WINDOW, " taps"),
            Self::WindowTooLarge { .. } => {
                text!(
                    WINDOW,
                    "must be at most N/2 and at most ",
                    MAX_WINDOW,
                    " taps"
                )
            }
            Self::StepNotPositive { .. } => text!(STEP, "must be positive"),
            Self::StepTooLarge { .. } => text!(STEP, "must be at most ", MAX_STEP_DEGREES, "°"),
            Self::RangeInverted { .. } => text!(RANGE, "min must be below max"),
            Self::RangeExcludesNeutral { .. } => {
                text!(RANGE, "must contain 0° (the neutral pose) strictly inside")
            }
            Self::RangeOutsideLimits { .. } => {
                text!(RANGE, "outside the axis' anatomical limits (Table 1)")
            }
            Self::StorageOverflow { .. } => {
                text!(RANGE, "does not fit the i16 millidegree storage")
            }
            Self::Degenerate { .. } => {
                text!(
                    SEED,
                    "the smoothed walk is flat, no motion to scale: choose another seed"
                )
            }
        }
    }

    /// A one-line description naming the offending field and the rule it
    /// broke, without the rejected value (static: for logs and compile-time
    /// errors; `Display` adds the value).
    #[must_use]
    pub const fn message(&self) -> &'static str {
        self.text().message
    }

    /// The rejected value.
    const fn rejected(&self) -> Value {
        match *self {
            Self::LengthTooShort { n, .. } | Self::LengthTooLong { n, .. } => Value::Count(n),
            Self::WindowTooSmall { window, .. } | Self::WindowTooLarge { window, .. } => {
                Value::Count(window as usize)
            }
            Self::StepNotPositive { step } | Self::StepTooLarge { step, .. } => Value::Angle(step),
            Self::RangeInverted { range }
            | Self::RangeExcludesNeutral { range }
            | Self::RangeOutsideLimits { range, .. }
            | Self::StorageOverflow { range } => Value::Range(range),
            Self::Degenerate { seed } => Value::Seed(seed),
        }
    }

    /// The limit that applies here where the rule cannot name it: it depends
    /// on the axis, on N or on the storage.
    const fn allowed(&self) -> Option<Value> {
        match *self {
            Self::WindowTooLarge { max, .. } => Some(Value::AtMost(max)),
            Self::RangeOutsideLimits { limits, .. } => Some(Value::Range(limits)),
            Self::StorageOverflow { .. } => Some(Value::Range(Mdeg16::RANGE)),
            _ => None,
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Count(n) => write!(f, "{n}"),
            Value::Seed(seed) => write!(f, "{seed}"),
            Value::Angle(angle) => write!(f, "{angle}"),
            Value::Range(range) => write!(f, "{range}"),
            Value::AtMost(max) => write!(f, "at most {max}"),
        }
    }
}

/// `field value: rule, allowed limit`; a range follows its field directly
/// (`range 5°..-5°`), any other value after ` = `.
impl fmt::Display for MotionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Text { field, rule, .. } = self.text();
        match self.rejected() {
            range @ Value::Range(_) => write!(f, "{field} {range}: {rule}")?,
            value => write!(f, "{field} = {value}: {rule}")?,
        }
        match self.allowed() {
            Some(limit) => write!(f, ", allowed {limit}"),
            None => Ok(()),
        }
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Value {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self {
            Value::Count(n) => defmt::write!(f, "{=usize}", n),
            Value::Seed(seed) => defmt::write!(f, "{=u32}", seed),
            Value::Angle(angle) => defmt::write!(f, "{}", angle),
            Value::Range(range) => defmt::write!(f, "{}", range),
            Value::AtMost(max) => defmt::write!(f, "at most {=u16}", max),
        }
    }
}

/// The same text as `Display`.
#[cfg(feature = "defmt")]
impl defmt::Format for MotionError {
    fn format(&self, f: defmt::Formatter<'_>) {
        let Text { field, rule, .. } = self.text();
        match self.rejected() {
            range @ Value::Range(_) => defmt::write!(f, "{=str} {}: {=str}", field, range, rule),
            value => defmt::write!(f, "{=str} = {}: {=str}", field, value, rule),
        }
        if let Some(limit) = self.allowed() {
            defmt::write!(f, ", allowed {}", limit);
        }
    }
}

impl core::error::Error for MotionError {}

/// A motion error together with the axis it concerns; displayed as the
/// axis' name and the error (`yaw range 5°..-5°: min must be below max`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisError {
    /// The axis whose configuration was rejected.
    pub axis: Axis,
    /// What was wrong.
    pub error: MotionError,
}

impl AxisError {
    /// Panics with the axis' name and the error's static
    /// [`message`](MotionError::message): in a `const` evaluation, the
    /// compile error of an invalid built-in configuration.
    pub(super) const fn panic(&self) -> ! {
        // Long enough for every axis name and message; were it not, the
        // message alone would still be told.
        let mut text = StrWriter::new([0u8; 128]);
        let mut writer = text.as_mut();
        let written = writer.write_str(self.axis.name()).is_ok()
            && writer.write_str(" ").is_ok()
            && writer.write_str(self.error.message()).is_ok();
        let message = if written {
            text.unsize().as_str()
        } else {
            self.error.message()
        };
        panic!("{}", message)
    }
}

impl fmt::Display for AxisError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.axis.name(), self.error)
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for AxisError {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "{=str} {}", self.axis.name(), self.error);
    }
}

impl core::error::Error for AxisError {}
