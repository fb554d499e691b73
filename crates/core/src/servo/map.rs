//! The frame path's angle → pulse → duty conversion: one servo's calibration
//! and its channel's duty scale, worked out once into 32-bit integer steps.
//!
//! The pulse that replies and logs show is exactly
//! [`ServoCalibration::pulse`]'s (whole µs); the duty is counted from the
//! exact pulse (ps), within one count of [`PwmTiming::duty_ps`] of
//! [`ServoCalibration::pulse_ps`], so a servo moves by the PWM's count,
//! not by 1 µs; in `i32` without a division for any usual calibration (in
//! 64 bits beyond).
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Angle to pulse to duty”).

use super::calibration::{Direction, Duty, PwmTiming, ServoCalibration};
use crate::units::{Angle, Microseconds};

/// Picoseconds per microsecond.
const PS_PER_US: i64 = 1_000_000;
/// Largest `|a·s|` (ps) of the 32-bit pulse path: room for the rounding
/// half (5·10⁵ ps) below 2³¹.
const NARROW_PS: i64 = (1 << 31) - (1 << 20);

/// One servo's angle → (pulse, duty) map; see the [module docs](self).
///
/// It holds only what it derives from the calibration: every method takes
/// the calibration it was made from (another gives meaningless values, never
/// a panic).
///
/// ```
/// use idle_head_core::servo::{Duty, PwmTiming, ServoCalibration, ServoMap};
/// use idle_head_core::{Angle, Axis, Microseconds};
/// let cal = ServoCalibration::hobby(Axis::Yaw);
/// let map = ServoMap::new(&cal, PwmTiming::SERVO_50HZ, 63_999);
/// let nine = Angle::from_degrees(9);
/// assert_eq!(map.pulse(&cal, nine), cal.pulse(nine)); // 1600 µs
/// assert_eq!(map.duty(&cal, nine), PwmTiming::SERVO_50HZ.duty_ps(cal.pulse_ps(nine), 63_999));
/// assert_eq!(map.duty(&cal, Angle::from_degrees(90)), Duty(6400)); // 2000 µs: clamped
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoMap {
    /// Angles outside `[lo, hi]` (m°) give the same clamped pulse as the ends.
    lo: i32,
    /// See `lo`.
    hi: i32,
    /// `±per_degree`: ps per m°, signed by the direction (32-bit form).
    ps_per_mdeg: i32,
    /// `k` of the module docs (0: the 64-bit duty form).
    duty_k: u32,
    /// `c` of the module docs.
    duty_c: u32,
    /// `b` of the module docs.
    duty_base: u32,
    /// The PWM period `T` (µs), for the 64-bit form.
    period: u32,
    /// Duty of `min_pulse`: the smallest written.
    duty_min: u16,
    /// Duty of `max_pulse`: the largest written.
    duty_max: u16,
    /// Counts per period `M`.
    max_duty: u16,
    /// `s` of the duty form.
    shift: u8,
    /// Whether `u` counts down from `hi` (a reversed servo).
    from_hi: bool,
    /// Whether the pulse takes the 32-bit form.
    narrow_pulse: bool,
}

impl ServoMap {
    /// The map of `cal` on a channel of `max_duty` counts per `pwm.period`.
    /// Total for any input; meant for a calibration that
    /// [`ServoCalibration::validate`] accepts and a non-zero period.
    #[must_use]
    pub fn new(cal: &ServoCalibration, pwm: PwmTiming, max_duty: u16) -> Self {
        let mut map = Self {
            lo: i32::MIN,
            hi: i32::MAX,
            ps_per_mdeg: 0,
            duty_k: 0,
            duty_c: 0,
            duty_base: 0,
            period: pwm.period.0,
            duty_min: pwm.duty(cal.min_pulse, max_duty).0,
            duty_max: pwm.duty(cal.max_pulse, max_duty).0,
            max_duty,
            shift: 0,
            from_hi: false,
            narrow_pulse: false,
        };
        map.narrow_pulse_form(cal);
        if map.narrow_pulse {
            map.narrow_duty_form(cal);
        }
        map
    }

    /// The angle domain and the 32-bit pulse form, if the calibration fits it.
    fn narrow_pulse_form(&mut self, cal: &ServoCalibration) {
        let per_degree = i64::from(cal.per_degree.0);
        if per_degree == 0 || cal.min_pulse.0 > cal.max_pulse.0 {
            return;
        }
        let s = match cal.direction {
            Direction::Normal => per_degree,
            Direction::Reversed => -per_degree,
        };
        // Pulse offsets (µs) from neutral that the pulse range, widened by
        // 1 µs, allows; the angles giving them, one m° further out.
        let neutral = i64::from(cal.neutral.0);
        let below = i64::from(cal.min_pulse.0) - 1 - neutral;
        let above = i64::from(cal.max_pulse.0) + 1 - neutral;
        let (a1, a2) = (below * PS_PER_US / s, above * PS_PER_US / s);
        let lo = a1.min(a2) - 1;
        let hi = a1.max(a2) + 1;
        self.lo = lo.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
        self.hi = hi.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
        let widest = lo.unsigned_abs().max(hi.unsigned_abs());
        let fits = widest
            .checked_mul(per_degree as u64)
            .is_some_and(|ps| ps <= NARROW_PS as u64);
        // Pulses fit `i32` with room for the offset.
        if fits && cal.max_pulse.0 <= i32::MAX as u32 / 2 {
            self.ps_per_mdeg = s as i32;
            self.narrow_pulse = true;
        }
    }

    /// `b`, `k`, `c` and `s` of the 32-bit duty form, if the domain fits it
    /// (after [`narrow_pulse_form`](Self::narrow_pulse_form): `|a·s|` of
    /// the domain below 2³¹). Two or three 64-bit divisions, no search.
    fn narrow_duty_form(&mut self, cal: &ServoCalibration) {
        self.from_hi = self.ps_per_mdeg < 0;
        let end = if self.from_hi { self.hi } else { self.lo };
        let range = u64::from(self.hi.abs_diff(self.lo));
        let per_mdeg = u64::from(self.ps_per_mdeg.unsigned_abs());
        let counts = u64::from(self.max_duty);
        let period = u64::from(self.period) * PS_PER_US as u64;
        let start =
            i64::from(cal.neutral.0) * PS_PER_US + i64::from(end) * i64::from(self.ps_per_mdeg);
        // The smaller end's pulse lies 1 µs below `min_pulse`, above 0 ps
        // for a sane calibration; any product that overflows: the 64-bit form.
        let x = u64::try_from(start)
            .ok()
            .and_then(|start| start.checked_mul(counts))
            .and_then(|x| x.checked_add(period / 2));
        let (Some(x), Some(num)) = (x, per_mdeg.checked_mul(counts)) else {
            return;
        };
        let (Some(base), Some(rem)) = (x.checked_div(period), x.checked_rem(period)) else {
            return;
        };
        // Counts over the domain, plus 1 for `c`: the largest s keeps about
        // q·2ˢ below 2³²; one step down if the ceilings push the sum over.
        let q = range.saturating_mul(num) / period + 1;
        let mut shift = 32u32.saturating_sub(64 - q.leading_zeros());
        loop {
            let scale = 1u64 << shift;
            let k = num.checked_mul(scale).map(|x| x.div_ceil(period));
            let c = rem.checked_mul(scale).map(|x| x.div_ceil(period));
            let (Some(k), Some(c)) = (k, c) else {
                return;
            };
            let sum = range.checked_mul(k).and_then(|x| x.checked_add(c));
            if sum.is_some_and(|x| x < 1 << 32) {
                // Error of the fraction < (1 + range)/2ˢ < 1 count.
                if 1 + range < scale && u16::try_from(base).is_ok() {
                    self.duty_k = k as u32;
                    self.duty_c = c as u32;
                    self.duty_base = base as u32;
                    self.shift = shift as u8;
                }
                return;
            }
            if shift == 0 {
                return;
            }
            shift -= 1;
        }
    }

    /// The pulse for `angle` in whole µs: [`ServoCalibration::pulse`],
    /// exactly (what replies and logs show; the duty keeps the finer
    /// pulse).
    #[must_use]
    #[inline]
    pub fn pulse(&self, cal: &ServoCalibration, angle: Angle) -> Microseconds {
        if !self.narrow_pulse {
            return cal.pulse(angle);
        }
        let a = angle.millidegrees().max(self.lo).min(self.hi);
        // |a·s| ≤ NARROW_PS on the domain (checked in `new`).
        let offset = div_1e6_round(a.wrapping_mul(self.ps_per_mdeg));
        let raw = cal.neutral.0 as i32 + offset;
        let (min, max) = (cal.min_pulse.0 as i32, cal.max_pulse.0 as i32);
        Microseconds(raw.max(min).min(max) as u32)
    }

    /// The duty of a whole-µs pulse: [`PwmTiming::duty`] of it clamped to
    /// `[min_pulse, max_pulse]`.
    #[must_use]
    pub fn pulse_duty(&self, cal: &ServoCalibration, pulse: Microseconds) -> Duty {
        let clamped = pulse.0.max(cal.min_pulse.0).min(cal.max_pulse.0);
        let timing = PwmTiming {
            period: Microseconds(self.period),
        };
        timing.duty(Microseconds(clamped), self.max_duty)
    }

    /// The pulse and the duty for `angle`: what the frame driver writes
    /// (the duty) and reports (both).
    #[must_use]
    #[inline]
    pub fn pulse_and_duty(&self, cal: &ServoCalibration, angle: Angle) -> (Microseconds, Duty) {
        (self.pulse(cal, angle), self.duty(cal, angle))
    }

    /// The duty for `angle`: [`PwmTiming::duty_ps`] of
    /// [`ServoCalibration::pulse_ps`] within one count (see the
    /// [module docs](self)).
    #[must_use]
    #[inline]
    pub fn duty(&self, cal: &ServoCalibration, angle: Angle) -> Duty {
        if self.duty_k == 0 {
            let timing = PwmTiming {
                period: Microseconds(self.period),
            };
            let duty = timing.duty_ps(cal.pulse_ps(angle), self.max_duty).0;
            return Duty(duty.max(self.duty_min).min(self.duty_max));
        }
        let a = angle.millidegrees().max(self.lo).min(self.hi);
        // u ≤ hi − lo, so c + u·k < 2³² (checked in `new`).
        let u = if self.from_hi {
            self.hi.wrapping_sub(a)
        } else {
            a.wrapping_sub(self.lo)
        } as u32;
        let fraction = self.duty_c.wrapping_add(u.wrapping_mul(self.duty_k)) >> self.shift;
        let duty = self.duty_base.saturating_add(fraction);
        Duty(
            duty.max(u32::from(self.duty_min))
                .min(u32::from(self.duty_max)) as u16,
        )
    }

    /// Counts per PWM period.
    #[must_use]
    pub const fn max_duty(&self) -> u16 {
        self.max_duty
    }

    /// An angle whose duty is the closest to `duty` (the middle of the angles
    /// that give it, if any do): where a servo that received `duty` stands
    /// in this calibration.
    #[must_use]
    pub fn angle_of_duty(&self, cal: &ServoCalibration, duty: Duty) -> Angle {
        let (lo, hi) = (i64::from(self.lo), i64::from(self.hi));
        let at = |a: i64| self.duty(cal, Angle::from_millidegrees(a as i32)).0;
        // The duty rises or falls with the angle: `key` rises.
        let rising = at(hi) >= at(lo);
        let key = |a: i64| {
            let d = at(a);
            if rising { d } else { u16::MAX - d }
        };
        let want = u32::from(if rising { duty.0 } else { u16::MAX - duty.0 });
        // The first angle in [lo, hi + 1] whose key reaches `want`.
        let first_at = |want: u32| {
            let (mut a, mut b) = (lo, hi + 1);
            while a < b {
                let mid = a + (b - a) / 2;
                if u32::from(key(mid)) >= want {
                    b = mid;
                } else {
                    a = mid + 1;
                }
            }
            a
        };
        let start = first_at(want);
        let end = first_at(want + 1);
        let angle = if start < end {
            start + (end - 1 - start) / 2
        } else {
            // No angle gives `duty` exactly: the nearer neighbour.
            let below = (start - 1).max(lo);
            let above = start.min(hi);
            let gap = |a: i64| u32::from(key(a)).abs_diff(want);
            if gap(below) <= gap(above) {
                below
            } else {
                above
            }
        };
        Angle::from_millidegrees(angle as i32)
    }
}

/// `x / 10⁶` rounded, halves away from zero, for `|x| < 2³¹ − 5·10⁵`.
#[inline]
fn div_1e6_round(x: i32) -> i32 {
    let q = div_1e6(x.unsigned_abs() + 500_000) as i32;
    if x < 0 { -q } else { q }
}

/// `⌊u / 10⁶⌋` for any `u32`, without a division.
///
/// The estimate `⌊⌊u/2¹²⌋·2147/2¹⁹⌋` uses 2147/2³¹ = 0.99978·10⁻⁶ and fits
/// `u32` (`2²⁰ · 2147 < 2³²`); it is low by less than 0.96 from the factor
/// (q < 4295) plus 0.005 from the first shift, so by at most 2 after the
/// floor: two remainder checks make it exact.
#[inline]
fn div_1e6(u: u32) -> u32 {
    let mut q = ((u >> 12) * 2147) >> 19;
    let mut r = u - q * 1_000_000;
    if r >= 1_000_000 {
        q += 1;
        r -= 1_000_000;
    }
    if r >= 1_000_000 {
        q += 1;
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::Axis;

    /// The hobby servo takes the 32-bit duty form at the Pico's 50, 200 and
    /// 333 Hz, with the documented bound on its excess (in counts).
    #[test]
    fn the_hobby_servo_takes_the_32_bit_form_at_every_pico_rate() {
        for (period, max_duty, bound) in [
            (20_000, 63_999, 0.2),
            (5000, 62_499, 0.35),
            (3003, 60_059, 0.7),
        ] {
            for direction in [Direction::Normal, Direction::Reversed] {
                let cal = ServoCalibration::hobby(Axis::Yaw).with_direction(direction);
                let pwm = PwmTiming {
                    period: Microseconds(period),
                };
                let map = ServoMap::new(&cal, pwm, max_duty);
                assert_ne!(map.duty_k, 0, "{period} µs");
                let excess = f64::from(map.hi - map.lo + 1) / f64::from(1u32 << map.shift);
                assert!(excess < bound, "{period} µs: {excess} (s = {})", map.shift);
            }
        }
    }
}
