//! What the behaviour refuses, in the user's units.
//!
//! Every error names the field, the rejected value and what is allowed:
//!
//! ```text
//! nod amplitude 30°: must be in 0.001°..20° (pitch's limits around its neutral pose)
//! nod: 6 cycles in 900 ms are 6.666 Hz: at most 4 Hz (at least 1500 ms for 6 cycles)
//! behaviour config `gaze.per_degree` = 900 ms: must be in 0..=100 ms
//! ```
//!
//! Frequencies, speeds and accelerations are printed from integers (no
//! float formatting: it would cost the firmware tens of kilobytes of flash).

use const_format::StrWriter;

use crate::text::Arg::{Int, Str, Text, Uint};
use crate::text::{self, Describe, display_from_describe};

use crate::axis::Axis;
use crate::driver::{DegreesPerSecond, DegreesPerSecondSquared};
use crate::gestures::GestureKind;
use crate::units::{Angle, AngleRange, MilliHertz, Millis};

/// A request or a configuration the behaviour refuses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum BehaviourError {
    /// A gesture's amplitude is outside what its axis allows around the
    /// neutral pose (see [`Shape`](crate::gestures::Shape): a dip or a
    /// swing positive, a lean of either sign).
    Amplitude {
        /// The gesture.
        kind: GestureKind,
        /// The rejected amplitude.
        amplitude: Angle,
        /// The amplitudes allowed.
        allowed: AngleRange,
    },
    /// A duration (or hold time) outside its range.
    Duration {
        /// The field (`nod duration`, `look hold`, ...).
        field: &'static str,
        /// The rejected duration.
        duration: Millis,
        /// The shortest allowed.
        min: Millis,
        /// The longest allowed.
        max: Millis,
    },
    /// A number of cycles outside `1..=max` (the gesture's
    /// [`max_cycles`](crate::gestures::Gesture::max_cycles)).
    Cycles {
        /// The gesture.
        kind: GestureKind,
        /// The rejected number.
        cycles: u8,
        /// The most allowed.
        max: u8,
    },
    /// More cycles than the frequency cap allows in the duration.
    TooFrequent {
        /// The gesture.
        kind: GestureKind,
        /// The cycles asked for.
        cycles: u8,
        /// In this duration.
        duration: Millis,
        /// The cap.
        max: MilliHertz,
    },
    /// The gesture needs more speed than its axis' gesture mode allows.
    TooFast {
        /// The gesture.
        kind: GestureKind,
        /// Its axis.
        axis: Axis,
        /// The peak speed it needs (rounded up).
        needed: DegreesPerSecond,
        /// The axis' gesture speed limit.
        max: DegreesPerSecond,
    },
    /// The gesture needs more acceleration than its axis' gesture mode allows.
    TooBrisk {
        /// The gesture.
        kind: GestureKind,
        /// Its axis.
        axis: Axis,
        /// The peak acceleration it needs (rounded up).
        needed: DegreesPerSecondSquared,
        /// The axis' gesture acceleration limit.
        max: DegreesPerSecondSquared,
    },
    /// Every gesture layer is busy (one playing, the others still fading
    /// out under it).
    Busy {
        /// When the first layer is free again.
        retry_in: Millis,
    },
    /// A configuration field outside its range.
    Config {
        /// The field, as written in the configuration (`gaze.base`).
        field: &'static str,
        /// Its unit (`ms`, `mHz`, `°/s`, ...).
        unit: &'static str,
        /// The rejected value.
        value: i64,
        /// The smallest allowed.
        min: i64,
        /// The largest allowed.
        max: i64,
    },
}

impl BehaviourError {
    /// The reply code for the console: `busy` when trying again later
    /// helps, `config` for a configuration, `range` otherwise.
    #[must_use]
    pub const fn code(&self) -> &'static str {
        match self {
            Self::Busy { .. } => "busy",
            Self::Config { .. } => "config",
            _ => "range",
        }
    }

    /// A one-line summary for logs (without the values or, for a
    /// configuration, the field; `Display` has them).
    #[must_use]
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Amplitude { .. } => "gesture amplitude outside what its axis allows",
            Self::Duration { field, .. } => field,
            Self::Config { .. } => "behaviour config value out of range",
            Self::Cycles { .. } => "gesture cycles out of range",
            Self::TooFrequent { .. } => "gesture cycles faster than the frequency cap",
            Self::TooFast { .. } => "gesture faster than the axis' gesture speed limit",
            Self::TooBrisk { .. } => "gesture faster than the axis' gesture acceleration limit",
            Self::Busy { .. } => "every gesture layer is busy",
        }
    }
}

impl BehaviourError {
    /// Panics with [`message`](Self::message), or for a configuration
    /// ``behaviour config `<field>` is out of range``: in a `const`
    /// evaluation, the compile error of an invalid built-in configuration.
    pub(super) const fn panic(&self) -> ! {
        // Long enough for every field; were it not, the summary alone would
        // still be told.
        let mut text = StrWriter::new([0u8; 96]);
        let mut writer = text.as_mut();
        let written = match self {
            Self::Config { field, .. } => {
                writer.write_str("behaviour config `").is_ok()
                    && writer.write_str(field).is_ok()
                    && writer.write_str("` is out of range").is_ok()
            }
            _ => false,
        };
        let message = if written {
            text.unsize().as_str()
        } else {
            self.message()
        };
        panic!("{}", message)
    }
}

/// `value` thousandths as `int.frac` without trailing zeros (`6.666`, `4`).
struct Milli(u64);

impl Describe for Milli {
    fn describe(&self, out: &mut dyn text::Text) {
        out.milli(self.0);
    }
}

impl Describe for BehaviourError {
    fn describe(&self, out: &mut dyn text::Text) {
        match *self {
            Self::Amplitude {
                kind,
                amplitude,
                allowed,
            } => out.fill(
                "{} amplitude {}: must be in {} ({}'s limits around its neutral pose)",
                &[
                    Str(kind.name()),
                    Text(&amplitude),
                    Text(&allowed),
                    Str(kind.axis().name()),
                ],
            ),
            Self::Duration {
                field,
                duration,
                min,
                max,
            } => out.fill(
                "{} {} ms: must be in {}..={} ms",
                &[
                    Str(field),
                    Uint(duration.0.into()),
                    Uint(min.0.into()),
                    Uint(max.0.into()),
                ],
            ),
            Self::Cycles {
                kind,
                cycles,
                max: 1,
            } => out.fill(
                "{} cycles {}: a {} has exactly 1",
                &[Str(kind.name()), Uint(cycles.into()), Str(kind.name())],
            ),
            Self::Cycles { kind, cycles, max } => out.fill(
                "{} cycles {}: must be in 1..={}",
                &[Str(kind.name()), Uint(cycles.into()), Uint(max.into())],
            ),
            Self::TooFrequent {
                kind,
                cycles,
                duration,
                max,
            } => too_frequent(out, kind, cycles, duration, max),
            Self::TooFast {
                kind,
                axis,
                needed,
                max,
            } => out.fill(
                "{}: needs {} °/s on {}: the gesture speed limit is {} °/s \
                 (lower the amplitude or the tempo)",
                &[
                    Str(kind.name()),
                    Uint(needed.0.into()),
                    Str(axis.name()),
                    Uint(max.0.into()),
                ],
            ),
            Self::TooBrisk {
                kind,
                axis,
                needed,
                max,
            } => out.fill(
                "{}: needs {} °/s² on {}: the gesture acceleration limit is {} °/s² \
                 (lower the amplitude or the tempo)",
                &[
                    Str(kind.name()),
                    Uint(needed.0.into()),
                    Str(axis.name()),
                    Uint(max.0.into()),
                ],
            ),
            Self::Busy { retry_in } => out.fill(
                "gestures: every layer is busy; try again in {} ms",
                &[Uint(retry_in.0.into())],
            ),
            Self::Config {
                field,
                unit,
                value,
                min,
                max,
            } => out.fill(
                "behaviour config `{}` = {} {}: must be in {}..={} {}",
                &[
                    Str(field),
                    Int(value),
                    Str(unit),
                    Int(min),
                    Int(max),
                    Str(unit),
                ],
            ),
        };
    }
}

display_from_describe!(BehaviourError);

/// [`BehaviourError::TooFrequent`]'s text.
fn too_frequent(
    out: &mut dyn text::Text,
    kind: GestureKind,
    cycles: u8,
    duration: Millis,
    max: MilliHertz,
) -> &mut dyn text::Text {
    let asked = u64::from(cycles) * 1_000_000 / u64::from(duration.0.max(1));
    let shortest = (u64::from(cycles) * 1_000_000).div_ceil(u64::from(max.0.max(1)));
    out.fill(
        "{}: {} cycles in {} ms are {} Hz: at most {} Hz (at least {} ms for {} cycles)",
        &[
            Str(kind.name()),
            Uint(cycles.into()),
            Uint(duration.0.into()),
            Text(&Milli(asked)),
            Text(&Milli(max.0.into())),
            Uint(shortest),
            Uint(cycles.into()),
        ],
    )
}

impl core::error::Error for BehaviourError {}
