//! Gestures as they play: a request resolved against the defaults and
//! checked (`plan`), and its offset at each frame ([`GesturePlan`]).
//!
//! Which gestures there are, their axes and defaults, is the
//! [gesture table](crate::gestures); how each moves is its
//! [`Shape`](super::shape). A gesture adds `E(φ) · A(φ) · c(φ)`: a C2
//! envelope, a cycle profile and the shape's carrier. A plan that plays
//! never exceeds its axis' gesture limits: faster cycles are refused
//! ([`BehaviourError::TooFrequent`], [`BehaviourError::TooFast`],
//! [`BehaviourError::TooBrisk`]). Per frame: 32-bit multiplies, no division.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Gestures”).

use crate::command::{GestureKind, GestureRequest};
use crate::driver::{DegreesPerSecond, DegreesPerSecondSquared};
use crate::units::{Angle, Millis, Percent};

use super::error::BehaviourError;
use super::fixed::{ONE, Span, mul, smootherstep};
use super::params::{BehaviourParams, LimitMode};
use super::shape::Shape;

/// Final lowering: the last cycle loses 0.4 of the trend (Q16).
const LOWERING: u32 = ONE * 2 / 5;

/// A gesture as it plays: what was asked for, resolved, and the constants
/// of its frame path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GesturePlan {
    /// Which gesture.
    pub kind: GestureKind,
    /// Peak of the first cycle.
    pub amplitude: Angle,
    /// Cycles.
    pub cycles: u8,
    /// Duration.
    pub duration: Millis,
    /// Intensity.
    pub intensity: Percent,
    /// The duration on the frame path's clock.
    pub(crate) span: Span,
    /// The gesture's shape (its row's, kept for the frame path).
    shape: Shape,
    /// Profile at `u = 0` and its fall over the gesture (m°).
    start: i32,
    fall: i32,
    /// Where the final lowering starts (Q16 cycles; `u32::MAX`: none).
    lower_from: u32,
    /// 1 / the envelope's ramp in cycles.
    ramp: u32,
}

/// Resolves `request` against the defaults and checks it.
///
/// # Errors
/// The first problem found, as a [`BehaviourError`].
pub(crate) const fn plan(
    params: &BehaviourParams,
    request: &GestureRequest,
) -> Result<GesturePlan, BehaviourError> {
    let kind = request.kind;
    let intensity = match request.intensity {
        Some(p) => p,
        None => params.config().defaults(kind).intensity,
    };
    let (cycles, duration_ms) = match tempo(params, request, intensity) {
        Ok(t) => t,
        Err(e) => return Err(e),
    };
    let a = match amplitude(params, request, intensity, cycles) {
        Ok(a) => a,
        Err(e) => return Err(e),
    };
    if let Err(e) = check_peaks(params, kind, a, cycles, duration_ms) {
        return Err(e);
    }
    let span = Span::new(BehaviourParams::micros(Millis(duration_ms as u32)));
    // Declination A·(1 − (φ − ½)/(4n)) = A·(1 + 1/(8n)) − (A/4)·u.
    let (start, fall, lower_from) = if cycles >= 2 {
        let den = 8 * cycles as i64;
        let eighth = (a as i64 + (a as i64).signum() * den / 2) / den;
        (
            a.saturating_add(eighth as i32),
            a / 4,
            (cycles as u32) * ONE - ONE * 3 / 2,
        )
    } else {
        (a, 0, u32::MAX)
    };
    Ok(GesturePlan {
        kind,
        amplitude: Angle::from_millidegrees(a),
        cycles: cycles as u8,
        duration: Millis(duration_ms as u32),
        intensity,
        span,
        start,
        fall,
        lower_from,
        shape: kind.shape(),
        ramp: kind.shape().ramp(),
    })
}

/// Cycles and duration (ms) of `request` at `intensity`.
const fn tempo(
    params: &BehaviourParams,
    request: &GestureRequest,
    intensity: Percent,
) -> Result<(u64, u64), BehaviourError> {
    let kind = request.kind;
    let config = params.config();
    let d = config.defaults(kind);
    let p = intensity.get() as u64;
    let f_mhz = d.slow.0 as u64 + (d.brisk.0 as u64).saturating_sub(d.slow.0 as u64) * p / 100;
    let f_mhz = if f_mhz == 0 { 1 } else { f_mhz };
    let row = kind.row();
    let field = row.fields.duration;
    let longest = config.longest_gesture;
    let asked = match request.cycles {
        Some(c) if c == 0 || c > row.max_cycles => {
            return Err(BehaviourError::Cycles {
                kind,
                cycles: c,
                max: row.max_cycles,
            });
        }
        c => c,
    };
    let (cycles, ms) = if let Some(duration) = request.duration {
        if duration.0 == 0 || duration.0 > longest.0 {
            return Err(too_long(field, duration.0 as u64, longest));
        }
        let n = if let Some(n) = asked {
            n as u64
        } else {
            let n = (duration.0 as u64 * f_mhz + 500_000) / 1_000_000;
            if n == 0 {
                1
            } else if n > row.max_cycles as u64 {
                row.max_cycles as u64
            } else {
                n
            }
        };
        (n, duration.0 as u64)
    } else {
        // Not asked: the defaults' count, within the gesture's own (a
        // posture has its one cycle; saved defaults may hold more).
        let n = if let Some(n) = asked {
            n as u64
        } else if d.cycles > row.max_cycles {
            row.max_cycles as u64
        } else {
            d.cycles as u64
        };
        let ms = (n * 1_000_000 + f_mhz / 2) / f_mhz;
        if ms > longest.0 as u64 {
            return Err(too_long(field, ms, longest));
        }
        (n, ms)
    };
    // n cycles in D ms at most at the cap: n·10⁶ ≤ cap·D.
    if cycles * 1_000_000 > config.max_frequency.0 as u64 * ms {
        return Err(BehaviourError::TooFrequent {
            kind,
            cycles: cycles as u8,
            duration: Millis(ms as u32),
            max: config.max_frequency,
        });
    }
    Ok((cycles, ms))
}

/// The first cycle's peak (m°): as asked, or the default at `intensity`
/// rising with `cycles`; checked against the axis' room.
const fn amplitude(
    params: &BehaviourParams,
    request: &GestureRequest,
    intensity: Percent,
    cycles: u64,
) -> Result<i32, BehaviourError> {
    let kind = request.kind;
    let amplitude = if let Some(a) = request.amplitude {
        a.millidegrees() as i64
    } else {
        // × (0.75 + p/200) × (1 + (min(n, 6) − 1)/20), rounded.
        let d = params.config().defaults(kind);
        let rising = if cycles > 6 { 6 } else { cycles };
        let num = d.amplitude.millidegrees() as i64
            * (150 + intensity.get() as i64)
            * (19 + rising as i64);
        let den = 200 * 20;
        (num + num.signum() * den / 2) / den
    };
    let room = params.room(kind.axis());
    let allowed = kind.shape().allowed(room);
    if amplitude < allowed.min.millidegrees() as i64
        || amplitude > allowed.max.millidegrees() as i64
    {
        return Err(BehaviourError::Amplitude {
            kind,
            amplitude: Angle::from_millidegrees(if amplitude < i32::MIN as i64 {
                i32::MIN
            } else if amplitude > i32::MAX as i64 {
                i32::MAX
            } else {
                amplitude as i32
            }),
            allowed,
        });
    }
    Ok(amplitude as i32)
}

/// The shape's peak speed and acceleration against the axis' gesture
/// limits (m°/s, m°/s²; see the module docs).
const fn check_peaks(
    params: &BehaviourParams,
    kind: GestureKind,
    amplitude: i32,
    cycles: u64,
    ms: u64,
) -> Result<(), BehaviourError> {
    let axis = kind.axis();
    let limits = params.limits(axis, LimitMode::Gesture);
    let shape = kind.shape();
    let (kv, ka) = shape.peak_factors();
    // The amplitude lies within the axis' room (the driver keeps limits
    // within ±2¹⁸ m°): capped at 2²⁰, with n ≤ 32 every product fits u64.
    let carrier = shape.carrier(amplitude.unsigned_abs() as u64);
    let carrier = if carrier > 1 << 20 { 1 << 20 } else { carrier };
    let (n, ms) = (cycles, if ms == 0 { 1 } else { ms });
    // Kv·a·2π·n/D with 2π·1000 = 6283; Ka·a·(2π·n/D)² with 4π²·1000 = 39 478.
    let speed = (kv * carrier * 6283 * n).div_ceil(1000 * ms);
    let accel = (ka * carrier * 39_478 * n * n).div_ceil(ms.saturating_mul(ms));
    if speed > limits.max_speed.0 as u64 * 1000 {
        return Err(BehaviourError::TooFast {
            kind,
            axis,
            needed: DegreesPerSecond(clamp_u32(speed.div_ceil(1000))),
            max: limits.max_speed,
        });
    }
    if accel > limits.max_accel.0 as u64 * 1000 {
        return Err(BehaviourError::TooBrisk {
            kind,
            axis,
            needed: DegreesPerSecondSquared(clamp_u32(accel.div_ceil(1000))),
            max: limits.max_accel,
        });
    }
    Ok(())
}

/// A duration outside `1..=longest`.
const fn too_long(field: &'static str, ms: u64, longest: Millis) -> BehaviourError {
    BehaviourError::Duration {
        field,
        duration: Millis(clamp_u32(ms)),
        min: Millis(1),
        max: longest,
    }
}

const fn clamp_u32(v: u64) -> u32 {
    if v > u32::MAX as u64 {
        u32::MAX
    } else {
        v as u32
    }
}

impl GesturePlan {
    /// The layer `t` µs after the start, for `t` before its end (`t <
    /// span`; the caller ends the layer there): its offset (m°) and its
    /// envelope `E` (Q16).
    #[inline]
    pub(crate) fn at(&self, t: u32) -> (i32, u32) {
        let u = self.span.progress(t);
        let n = self.cycles as u32;
        // φ < n: u < 1.
        let phi = n * u;
        let tail = n * ONE - phi;
        let envelope = if phi * self.ramp < ONE {
            smootherstep(phi * self.ramp)
        } else if tail * self.ramp < ONE {
            smootherstep(tail * self.ramp)
        } else {
            ONE
        };
        let mut amplitude = self.start - mul(self.fall, u);
        if phi > self.lower_from {
            let lowering = mul(LOWERING as i32, smootherstep(phi - self.lower_from));
            amplitude -= mul(amplitude, lowering as u32);
        }
        // Between the ramps the envelope is 1 (and `mul` by 1 exact).
        let scaled = if envelope == ONE {
            amplitude
        } else {
            mul(amplitude, envelope)
        };
        let value = self.shape.value(scaled, phi);
        (value, envelope)
    }
}
