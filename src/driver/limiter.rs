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
        let target = bound(target.millidegrees() as i64 * MICRO_PER_MILLI, p.lo, p.hi);
        // |target|, |pos| ≤ 2^31 · 1000 < 2^41: differences < 2^42.
        let target_vel = target - self.last_target;
        // Error before this frame's target motion: with perfect tracking it is
        // 0 and the wanted step is exactly the target's step.
        let err = self.last_target - self.pos;
        self.last_target = target;
        let closing = err
            .unsigned_abs()
            .min(brake_speed(err.unsigned_abs(), p.max_accel)) as i64;
        let wanted = target_vel + err.signum() * closing;
        // vel ∈ [−max_step, max_step] ⇒ the accel window meets the speed window.
        let vel = bound(wanted, self.vel - p.max_accel, self.vel + p.max_accel);
        let vel = bound(vel, -p.max_step, p.max_step);
        let pos = bound(self.pos + vel, p.lo, p.hi);
        self.vel = pos - self.pos;
        self.pos = pos;
        // Round to the nearest m° (halves up); lo, hi are whole m°, so the
        // result stays inside the limits.
        Angle::from_millidegrees((pos + MICRO_PER_MILLI / 2).div_euclid(MICRO_PER_MILLI) as i32)
    }
}

/// `x` limited to `[lo, hi]` (`hi` wins if `lo > hi`; unlike `Ord::clamp`,
/// this has no panic path).
fn bound(x: i64, lo: i64, hi: i64) -> i64 {
    x.max(lo).min(hi)
}

/// Largest step `v` after which the limiter can still stop within `dist`
/// decelerating by at most `accel` per frame: the steps v, v − a, v − 2a, ...
/// down to the last positive one must sum to at most `dist`.
///
/// With `k` further steps after this one (v ∈ (k·a, (k+1)·a]) the sum is
/// S(v) = (k+1)·v − a·k(k+1)/2, increasing in v, so on segment `k` the largest
/// v is min((k+1)·a, ⌊(dist + a·k(k+1)/2) / (k+1)⌋), valid if above k·a. The
/// continuous estimate k ≈ (√(2·a·d + a²/4) − a/2) / a is within one segment
/// of the answer; the two segments either side are checked too.
fn brake_speed(dist: u64, accel: i64) -> u64 {
    let accel = accel.unsigned_abs().max(1) as u128;
    let dist = dist as u128;
    // accel ≤ 2^48, dist < 2^43: the radicand < 2^97, every product below < 2^110.
    let estimate = (2 * accel * dist + accel * accel / 4)
        .isqrt()
        .saturating_sub(accel / 2)
        / accel;
    let mut best = 0;
    let mut segment = estimate.saturating_sub(2);
    while segment <= estimate + 2 {
        let steps = segment + 1;
        let base = accel * segment * steps / 2;
        let speed = (steps * accel).min((dist + base).checked_div(steps).unwrap_or(0));
        if speed > segment * accel && speed > best {
            best = speed;
        }
        segment += 1;
    }
    // best ≤ (dist + base) / steps ≤ dist + accel < 2^64.
    best.min(u64::MAX as u128) as u64
}
