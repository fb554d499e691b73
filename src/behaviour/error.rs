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

use core::fmt;

use crate::axis::Axis;
use crate::command::GestureKind;
use crate::driver::{DegreesPerSecond, DegreesPerSecondSquared};
use crate::units::{Angle, AngleRange, Millis};

use super::config::MilliHertz;

/// A request or a configuration the behaviour refuses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum BehaviourError {
    /// A gesture's amplitude is outside what its axis allows around the
    /// neutral pose (nods and shakes: positive; tilts: not zero).
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
    /// A number of cycles outside `1..=max`.
    Cycles {
        /// The gesture.
        kind: GestureKind,
        /// The rejected number.
        cycles: u8,
        /// The most allowed.
        max: u8,
    },
    /// A tilt has exactly one cycle.
    TiltCycles {
        /// The rejected number.
        cycles: u8,
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
        /// The whole rule, for logs and compile-time errors
        /// (``behaviour config `gaze.base`: must be in 0..=5000 ms``).
        rule: &'static str,
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

    /// A one-line summary for logs and compile-time errors (without the
    /// values; `Display` has them).
    #[must_use]
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Amplitude { .. } => "gesture amplitude outside what its axis allows",
            Self::Duration { field, .. } => field,
            Self::Config { rule, .. } => rule,
            Self::Cycles { .. } => "gesture cycles out of range",
            Self::TiltCycles { .. } => "a tilt has exactly one cycle",
            Self::TooFrequent { .. } => "gesture cycles faster than the frequency cap",
            Self::TooFast { .. } => "gesture faster than the axis' gesture speed limit",
            Self::TooBrisk { .. } => "gesture faster than the axis' gesture acceleration limit",
            Self::Busy { .. } => "every gesture layer is busy",
        }
    }
}

/// `value` thousandths as `int.frac` without trailing zeros (`6.666`, `4`).
struct Milli(u64);

impl fmt::Display for Milli {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (int, mut frac) = (self.0 / 1000, self.0 % 1000);
        if frac == 0 {
            return write!(f, "{int}");
        }
        let mut digits = 3;
        while frac % 10 == 0 {
            frac /= 10;
            digits -= 1;
        }
        write!(f, "{int}.{frac:0digits$}")
    }
}

impl fmt::Display for BehaviourError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Amplitude {
                kind,
                amplitude,
                allowed,
            } => write!(
                f,
                "{} amplitude {amplitude}: must be in {allowed} ({}'s limits around its neutral pose)",
                kind.name(),
                kind.axis().name()
            ),
            Self::Duration {
                field,
                duration,
                min,
                max,
            } => write!(
                f,
                "{field} {} ms: must be in {}..={} ms",
                duration.0, min.0, max.0
            ),
            Self::Cycles { kind, cycles, max } => {
                write!(f, "{} cycles {cycles}: must be in 1..={max}", kind.name())
            }
            Self::TiltCycles { cycles } => write!(f, "tilt cycles {cycles}: a tilt has exactly 1"),
            Self::TooFrequent {
                kind,
                cycles,
                duration,
                max,
            } => {
                let asked = u64::from(cycles) * 1_000_000 / u64::from(duration.0.max(1));
                let shortest = (u64::from(cycles) * 1_000_000).div_ceil(u64::from(max.0.max(1)));
                write!(
                    f,
                    "{}: {cycles} cycles in {} ms are {} Hz: at most {} Hz (at least {shortest} ms for {cycles} cycles)",
                    kind.name(),
                    duration.0,
                    Milli(asked),
                    Milli(u64::from(max.0))
                )
            }
            Self::TooFast {
                kind,
                axis,
                needed,
                max,
            } => write!(
                f,
                "{}: needs {} °/s on {}: the gesture speed limit is {} °/s (lower the amplitude or the tempo)",
                kind.name(),
                needed.0,
                axis.name(),
                max.0
            ),
            Self::TooBrisk {
                kind,
                axis,
                needed,
                max,
            } => write!(
                f,
                "{}: needs {} °/s² on {}: the gesture acceleration limit is {} °/s² (lower the amplitude or the tempo)",
                kind.name(),
                needed.0,
                axis.name(),
                max.0
            ),
            Self::Busy { retry_in } => write!(
                f,
                "gestures: every layer is busy; try again in {} ms",
                retry_in.0
            ),
            Self::Config {
                field,
                unit,
                rule: _,
                value,
                min,
                max,
            } => write!(
                f,
                "behaviour config `{field}` = {value} {unit}: must be in {min}..={max} {unit}"
            ),
        }
    }
}

impl core::error::Error for BehaviourError {}
