//! Speed and acceleration limiter on the commanded angle of one axis.
//!
//! State in microdegrees (µ°) and µ° per frame so that limits stay exact at
//! high frame rates; the output is rounded to millidegrees.

use crate::units::Angle;

/// µ° per m°.
const MICRO_PER_MILLI: i64 = 1000;

/// Limits of one axis in frame units (µ°, µ°/frame, µ°/frame²).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct SlewParams {
    /// Largest step per frame, µ°/frame (≥ 1, ≤ 2^48).
    pub(crate) max_step: i64,
    /// Largest change of step per frame, µ°/frame² (≥ 1, ≤ 2^48).
    pub(crate) max_accel: i64,
    /// Mechanical limits, µ°.
    pub(crate) lo: i64,
    /// Mechanical limits, µ°.
    pub(crate) hi: i64,
}

/// Follows a target angle within speed, acceleration and position limits.
///
/// It feeds the target's own velocity forward, so a target that already moves
/// within the limits is followed exactly (no lag); otherwise it accelerates at
/// most `max_accel`, moves at most `max_step`, and brakes in time to stop on
/// the target (the braking speed for distance d is the largest v with
/// v²/2a + v/2 ≤ d, the distance covered by steps v, v − a, v − 2a, ...).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Slew {
    pos: i64,
    vel: i64,
    last_target: i64,
}

/// The default is at rest at 0°, where the neutral pulse puts the servo.
impl Slew {
    /// One frame towards `target`; returns the new angle.
    pub(crate) fn step(&mut self, target: Angle, p: &SlewParams) -> Angle {
        let target = (target.millidegrees() as i64 * MICRO_PER_MILLI).clamp(p.lo, p.hi);
        // |target|, |pos| ≤ 2^31 · 1000 < 2^41: differences < 2^42.
        let target_vel = target - self.last_target;
        self.last_target = target;
        let err = target - self.pos;
        let closing = err
            .unsigned_abs()
            .min(brake_speed(err.unsigned_abs(), p.max_accel)) as i64;
        let wanted = target_vel + err.signum() * closing;
        // vel ∈ [−max_step, max_step] ⇒ the accel window meets the speed window.
        let vel = wanted
            .clamp(self.vel - p.max_accel, self.vel + p.max_accel)
            .clamp(-p.max_step, p.max_step);
        let pos = (self.pos + vel).clamp(p.lo, p.hi);
        self.vel = pos - self.pos;
        self.pos = pos;
        // Round to the nearest m° (halves up); lo, hi are whole m°, so the
        // result stays inside the limits.
        Angle::from_millidegrees((pos + MICRO_PER_MILLI / 2).div_euclid(MICRO_PER_MILLI) as i32)
    }
}

/// Largest speed that can still stop within `dist` at deceleration `accel`:
/// ⌊√(2·a·d + a²/4) − a/2⌋ (a ≤ 2^48, d < 2^43: the radicand < 2^97).
fn brake_speed(dist: u64, accel: i64) -> u64 {
    let a = accel.unsigned_abs() as u128;
    let root = (2 * a * dist as u128 + a * a / 4).isqrt();
    // root < 2^49; root ≥ a/2 since the radicand ≥ a²/4.
    (root.saturating_sub(a / 2)) as u64
}
