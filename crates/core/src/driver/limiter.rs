//! Speed and acceleration limiter on the commanded angle of one axis.
//!
//! State in microdegrees (µ°) and µ° per frame, `i32` throughout (angle
//! limits within ±360°, [`MAX_LIMIT_MDEG`]; distances within [`SPAN`]); the
//! output is rounded to millidegrees. The braking speed is exact (the
//! largest speed whose decelerating steps fit the distance), and the
//! position limits are braked for like a target, so the head never reaches
//! a limit faster than it can stop there. A target tracked exactly within
//! the clear band takes the common case: one comparison, no braking.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The limiter's arithmetic”).

use crate::units::Angle;

/// µ° per m°.
const MICRO_PER_MILLI: i32 = 1000;

/// Widest angle limit the limiter takes, either side of neutral: 360° in m°.
pub(crate) const MAX_LIMIT_MDEG: i32 = 360_000;

/// Largest distance between two positions within the limits: 720° in µ°.
pub(crate) const SPAN: u32 = 2 * MAX_LIMIT_MDEG as u32 * MICRO_PER_MILLI as u32;

/// Limits of one axis in frame units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct SlewParams {
    /// Largest step per frame, µ°/frame, in `1..=SPAN`.
    pub(crate) max_step: u32,
    /// Largest change of step per frame, µ°/frame², in `1..=2·SPAN`.
    pub(crate) max_accel: u32,
    /// `min(max_step, max_accel)`: the largest target step followed as it is
    /// (see the module docs' common case).
    follow: u32,
    /// The clear band, µ°: from a position within it (`clear_lo ≤ pos ≤
    /// clear_hi`) any step up to `max_step` is within the braking speed for
    /// both position limits (empty when the limits are too close for that).
    clear_lo: i32,
    clear_hi: i32,
    /// Mechanical limits, m°, within ±[`MAX_LIMIT_MDEG`].
    pub(crate) lo: i32,
    /// Mechanical limits, m°, within ±[`MAX_LIMIT_MDEG`].
    pub(crate) hi: i32,
}

/// The per-frame rates of one axis' motion limits, without its angle
/// limits: what a change of motion limits computes (its divisions), so that
/// limits used again and again (the behaviour's modes) are computed once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct SlewRates {
    max_step: u32,
    max_accel: u32,
    /// The braking distance of the fastest step, µ°, at most [`SPAN`].
    reach: i32,
}

impl SlewRates {
    /// `step` µ°/frame and `accel` µ°/frame², capped as the module docs
    /// explain.
    pub(crate) const fn new(step: u64, accel: u64) -> Self {
        let step = if step > SPAN as u64 {
            SPAN
        } else {
            step as u32
        };
        let accel = if accel > 2 * SPAN as u64 {
            2 * SPAN
        } else {
            accel as u32
        };
        let max_step = if step == 0 { 1 } else { step };
        let max_accel = if accel == 0 { 1 } else { accel };
        // The braking distance of the fastest step: a step `v ≤ max_step`
        // is within the braking speed for a distance `d` when
        // `2·a·d ≥ (v + a)²` (module docs), so for every `d ≥ reach`.
        // max_step + max_accel ≤ 3·SPAN < 2³²: the square fits u64.
        let sum = max_step as u64 + max_accel as u64;
        let reach = (sum * sum).div_ceil(2 * max_accel as u64);
        Self {
            max_step,
            max_accel,
            reach: if reach > SPAN as u64 {
                SPAN as i32
            } else {
                reach as i32
            },
        }
    }
}

impl SlewParams {
    /// The limits of `step` µ°/frame and `accel` µ°/frame² between `lo` and
    /// `hi` (m°, validated to lie within ±[`MAX_LIMIT_MDEG`]), capped as the
    /// module docs explain.
    pub(crate) const fn new(step: u64, accel: u64, lo: i32, hi: i32) -> Self {
        Self::with_rates(SlewRates::new(step, accel), lo, hi)
    }

    /// The limits of `rates` between `lo` and `hi` (m°, validated to lie
    /// within ±[`MAX_LIMIT_MDEG`]). No division: a switch between rates
    /// computed before is a few additions.
    pub(crate) const fn with_rates(rates: SlewRates, lo: i32, hi: i32) -> Self {
        let SlewRates {
            max_step,
            max_accel,
            reach,
        } = rates;
        // |lo|, |hi| ≤ MAX_LIMIT and reach ≤ SPAN: the band's ends are
        // within ±1.08·10⁹ µ°, inside i32.
        let clear_lo = lo * MICRO_PER_MILLI + reach;
        let clear_hi = hi * MICRO_PER_MILLI - reach;
        let (clear_lo, clear_hi) = if clear_lo > clear_hi {
            (i32::MAX, i32::MIN)
        } else {
            (clear_lo, clear_hi)
        };
        Self {
            max_step,
            max_accel,
            follow: if max_step < max_accel {
                max_step
            } else {
                max_accel
            },
            clear_lo,
            clear_hi,
            lo,
            hi,
        }
    }
}

/// Follows a target angle within speed, acceleration and position limits.
///
/// It feeds the target's own velocity forward, so a target that already moves
/// within the limits is followed exactly (no lag); otherwise it accelerates at
/// most `max_accel`, moves at most `max_step`, and brakes in time to stop on
/// the target and before the position limits. A speed above `max_step`
/// (after the limit was lowered) comes down by `max_accel` per frame. A
/// position outside the limits (after a change of calibration) moves back in
/// and never further out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Slew {
    /// Position, µ°.
    pos: i32,
    /// Last step, µ°/frame.
    vel: i32,
    /// Last target (clamped to the limits), µ°.
    last_target: i32,
}

/// The default is at rest at 0°, where the neutral pulse puts the servo.
impl Slew {
    /// At rest at `angle` moving by `vel` µ°/frame, the target there too
    /// (both clamped to the limiter's range).
    pub(crate) const fn anchored(angle: Angle, vel: i32) -> Self {
        let m = angle.millidegrees();
        let m = if m < -MAX_LIMIT_MDEG {
            -MAX_LIMIT_MDEG
        } else if m > MAX_LIMIT_MDEG {
            MAX_LIMIT_MDEG
        } else {
            m
        };
        let v = if vel < -(SPAN as i32) {
            -(SPAN as i32)
        } else if vel > SPAN as i32 {
            SPAN as i32
        } else {
            vel
        };
        Self {
            pos: m * MICRO_PER_MILLI,
            vel: v,
            last_target: m * MICRO_PER_MILLI,
        }
    }

    /// The current angle, rounded to m° as [`step`](Self::step) returns it.
    pub(crate) const fn angle(&self) -> Angle {
        Angle::from_millidegrees(round_to_mdeg(self.pos))
    }

    /// Stops where it is: at rest, its target there too (the servo was left
    /// without pulses).
    pub(crate) const fn halt(&mut self) {
        self.vel = 0;
        self.last_target = self.pos;
    }

    /// The last step, µ°/frame.
    pub(crate) const fn velocity(&self) -> i32 {
        self.vel
    }

    /// The frames come `to` µs apart instead of `from`: the last step as
    /// the same speed in the new frames (`vel · to / from`, rounded), so
    /// that a target moving at that speed is followed on as it was.
    pub(crate) fn rescale(&mut self, to: u32, from: u32) {
        if from == 0 || to == from {
            return;
        }
        // |vel| ≤ SPAN < 2³⁰, to < 2³²: the product fits i64.
        let num = i64::from(self.vel) * i64::from(to);
        let den = i64::from(from);
        let half = if num < 0 { -(den / 2) } else { den / 2 };
        let vel = (num + half).checked_div(den).unwrap_or(0);
        self.vel = vel.clamp(-i64::from(SPAN), i64::from(SPAN)) as i32;
    }

    /// Whether the limits `p` can take over from the next frame on without a
    /// step beyond them: the speed is within `p`'s and, decelerating at `p`'s
    /// acceleration, the axis can still stop before the angle limit it moves
    /// towards. (Otherwise the next step would have to brake harder than
    /// `p` allows, or pass the angle limit: the limits in use must stay until
    /// the axis has slowed down.)
    pub(crate) fn can_take(&self, p: &SlewParams) -> bool {
        let speed = self.vel.unsigned_abs();
        if speed > p.max_step {
            return false;
        }
        // Both within ±MAX_LIMIT: the differences fit.
        let room = match self.vel {
            0 => return true,
            v if v > 0 => p.hi * MICRO_PER_MILLI - self.pos,
            _ => self.pos - p.lo * MICRO_PER_MILLI,
        };
        // The next step is at least `speed − a` towards the limit, and the
        // braking speed for the room left now is the most it may be.
        speed.saturating_sub(p.max_accel) <= brake_speed(room.max(0).unsigned_abs(), p.max_accel)
    }

    /// One frame towards `target`; returns the new angle.
    #[inline]
    pub(crate) fn step(&mut self, target: Angle, p: &SlewParams) -> Angle {
        let mdeg = target.millidegrees().max(p.lo).min(p.hi);
        let target = mdeg * MICRO_PER_MILLI;
        // Both within ±MAX_LIMIT: the difference fits.
        let target_vel = target - self.last_target;
        let speed = target_vel.unsigned_abs();
        if self.pos == self.last_target
            && speed <= p.follow
            && target_vel.abs_diff(self.vel) <= p.max_accel
        {
            self.last_target = target;
            self.pos = target;
            self.vel = target_vel;
            return Angle::from_millidegrees(mdeg);
        }
        self.limited_step(target, target_vel, p)
    }

    /// The step when the target is off or moves beyond the limits.
    #[inline(never)]
    fn limited_step(&mut self, target: i32, target_vel: i32, p: &SlewParams) -> Angle {
        // The common case's faster steps, in the clear band (module docs).
        if self.pos == self.last_target
            && target_vel.unsigned_abs() <= p.max_step
            && target_vel.abs_diff(self.vel) <= p.max_accel
            && self.pos >= p.clear_lo
            && self.pos <= p.clear_hi
        {
            self.last_target = target;
            self.pos = target;
            self.vel = target_vel;
            return Angle::from_millidegrees(round_to_mdeg(target));
        }
        // Error before this frame's target motion: with perfect tracking it is
        // 0 and the wanted step is exactly the target's step.
        let err = self.last_target - self.pos;
        self.last_target = target;
        let v = self.vel;
        // The speed limit; a speed above it comes down at the acceleration limit.
        let limit = p.max_step.max(v.unsigned_abs().saturating_sub(p.max_accel));
        // closing ≤ |err| ≤ SPAN. A closing speed of `limit + |target_vel|`
        // or more takes the step to the limit whatever it is, so the exact
        // value is only needed below that.
        let enough = limit + target_vel.unsigned_abs();
        let closing = brake_speed_up_to(err.unsigned_abs(), p.max_accel, enough) as i32;
        let wanted = if err < 0 {
            target_vel - closing
        } else {
            target_vel + closing
        };
        // max_accel ≤ 2·SPAN < 2³¹. v ± a is only formed when it lies
        // between v and `wanted`, so it fits.
        let a = p.max_accel as i32;
        let vel = if wanted.abs_diff(v) <= p.max_accel {
            wanted
        } else if wanted > v {
            v + a
        } else {
            v - a
        };
        let vel = vel.max(-(limit as i32)).min(limit as i32);
        // Braking for the position limits (a position outside them does not
        // move further out).
        let (lo, hi) = (p.lo * MICRO_PER_MILLI, p.hi * MICRO_PER_MILLI);
        let room =
            |d: i32, speed: u32| brake_speed_up_to(d.max(0).unsigned_abs(), p.max_accel, speed);
        let vel = if vel > 0 {
            room(hi - self.pos, vel.unsigned_abs()) as i32
        } else {
            -(room(self.pos - lo, vel.unsigned_abs()) as i32)
        };
        // Within the limits, or no further out than the position already is.
        let (lo, hi) = (lo.min(self.pos), hi.max(self.pos));
        let pos = (self.pos + vel).max(lo).min(hi);
        self.vel = pos - self.pos;
        self.pos = pos;
        Angle::from_millidegrees(round_to_mdeg(pos))
    }
}

/// `pos` µ° to the nearest m° (halves up), for `|pos| ≤ SPAN/2`; the
/// limits are whole m°, so a position inside them stays inside.
///
/// With `u = pos + 500 + 360 000 000 < 2³⁰`, `⌊u/1000⌋` without a division:
/// `q₀ = ⌊⌊u/2¹⁶⌋·67 108/2¹⁰⌋` (67 108/1024 = 65.5352 < 2¹⁶/1000) is low by
/// less than 81, so `r = u − 1000·q₀ < 81 000`, and `⌊r·1049/2²⁰⌋`
/// (1049/2²⁰ = 1.0004/1000) is `⌊r/1000⌋` or one more, which the last
/// comparison removes.
const fn round_to_mdeg(pos: i32) -> i32 {
    const OFFSET: i32 = MAX_LIMIT_MDEG * MICRO_PER_MILLI;
    let u = (pos + MICRO_PER_MILLI / 2 + OFFSET) as u32;
    let q0 = ((u >> 16) * 67_108) >> 10;
    let r = u - q0 * 1000;
    let mut q = q0 + ((r * 1049) >> 20);
    if q * 1000 > u {
        q -= 1;
    }
    q as i32 - MAX_LIMIT_MDEG
}

/// `min(enough, brake_speed(dist, accel))`, computing the braking speed
/// only when it may be below `enough`: it is at least `min(dist, accel)`,
/// and at least `v` when `2·a·dist ≥ (v + a)²` (the steps v, v − a, … sum to
/// at most `(v + a)²/2a`), which two 64-bit products tell.
fn brake_speed_up_to(dist: u32, accel: u32, enough: u32) -> u32 {
    if enough <= dist.min(accel) {
        return enough;
    }
    let reach = u64::from(enough) + u64::from(accel);
    if 2 * u64::from(dist) * u64::from(accel) >= reach * reach {
        return enough;
    }
    brake_speed(dist, accel).min(enough)
}

/// Largest step `v` after which the limiter can still stop within `dist`
/// decelerating by at most `accel` per frame (see the module docs);
/// `dist ≤ SPAN`, `accel ≥ 1`.
fn brake_speed(dist: u32, accel: u32) -> u32 {
    if dist <= accel {
        // One step covers it.
        return dist;
    }
    let q = dist.checked_div(accel).unwrap_or(dist);
    // 2q ≤ 2·SPAN < 2³¹; r ≤ 37 947, so r(r + 1) fits.
    let twice = 2 * q;
    let r = twice.isqrt();
    let k = if r * (r + 1) <= twice { r } else { r - 1 };
    // T(k) ≤ a·q ≤ dist.
    let base = accel * (k * (k + 1) / 2);
    (dist + base).checked_div(k + 1).unwrap_or(dist)
}
