//! The limiter's specification as a model in wide arithmetic (`i64`, and the
//! braking speed in `u128` by a search around the continuous estimate), for
//! comparison with the driver's 32-bit limiter.

/// Limits in frame units, uncapped: µ°/frame, µ°/frame², µ°.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub step: i64,
    pub accel: i64,
    pub lo: i64,
    pub hi: i64,
}

impl Limits {
    /// The limits of `speed` °/s and `accel` °/s² at frames of `frame_us`
    /// between `lo` and `hi` m°, as the driver computes them.
    pub fn new(speed: u32, accel: u32, frame_us: u32, lo: i32, hi: i32) -> Self {
        let f = i128::from(frame_us);
        Self {
            step: i64::from(speed) * i64::from(frame_us),
            accel: (i128::from(accel) * f * f / 1_000_000) as i64,
            lo: i64::from(lo) * 1000,
            hi: i64::from(hi) * 1000,
        }
    }
}

/// The limiter's state: position, last step, last target (µ°).
#[derive(Clone, Copy, Debug, Default)]
pub struct Model {
    pos: i64,
    vel: i64,
    last_target: i64,
}

impl Model {
    /// One frame towards `target` (m°); the new angle (m°).
    ///
    /// The target is clamped to the limits; its step is fed forward and the
    /// error closed at most at the braking speed; the step changes by at most
    /// `accel` and is at most `step` (a higher speed comes down by `accel`);
    /// a step towards a limit is at most the braking speed for the distance
    /// to it; the position stays within the limits.
    pub fn step(&mut self, target: i32, l: &Limits) -> i32 {
        let target = (i64::from(target) * 1000).clamp(l.lo, l.hi);
        let target_vel = target - self.last_target;
        let err = self.last_target - self.pos;
        self.last_target = target;
        let closing = brake_speed(err.unsigned_abs(), l.accel) as i64;
        let wanted = target_vel + err.signum() * closing.min(err.abs());
        let v = self.vel;
        let vel = wanted.clamp(v - l.accel, v + l.accel);
        let limit = l.step.max(v.abs() - l.accel);
        let vel = vel.clamp(-limit, limit);
        let vel = if vel > 0 {
            vel.min(brake_speed((l.hi - self.pos).max(0).unsigned_abs(), l.accel) as i64)
        } else {
            vel.max(-(brake_speed((self.pos - l.lo).max(0).unsigned_abs(), l.accel) as i64))
        };
        let pos = (self.pos + vel).clamp(l.lo.min(self.pos), l.hi.max(self.pos));
        self.vel = pos - self.pos;
        self.pos = pos;
        (pos + 500).div_euclid(1000) as i32
    }
}

/// Largest step `v` after which a stop within `dist` is possible decelerating
/// by at most `accel` per frame: the steps v, v − a, v − 2a, ... (the
/// positive ones) sum to at most `dist`.
///
/// With `k` further steps after this one (v ∈ (k·a, (k+1)·a]) the sum is
/// S(v) = (k+1)·v − a·k(k+1)/2, so on segment `k` the largest v is
/// min((k+1)·a, ⌊(dist + a·k(k+1)/2)/(k+1)⌋), valid if above k·a. The
/// continuous estimate k ≈ (√(2·a·d + a²/4) − a/2)/a is within one segment of
/// the answer; the segments either side are checked too.
pub fn brake_speed(dist: u64, accel: i64) -> u64 {
    let accel = u128::from(accel.unsigned_abs().max(1));
    let dist = u128::from(dist);
    let estimate = (2 * accel * dist + accel * accel / 4)
        .isqrt()
        .saturating_sub(accel / 2)
        / accel;
    let mut best = 0;
    let mut segment = estimate.saturating_sub(2);
    while segment <= estimate + 2 {
        let steps = segment + 1;
        let base = accel * segment * steps / 2;
        let speed = (steps * accel).min((dist + base) / steps);
        if speed > segment * accel && speed > best {
            best = speed;
        }
        segment += 1;
    }
    best as u64
}

#[test]
fn braking_speed_stops_within_the_distance_and_no_faster_speed_does() {
    for accel in [1i64, 7, 240, 240_000, 1 << 30] {
        for dist in (0u64..2000).chain([99_999, 1 << 20, 720_000_000]) {
            let v = brake_speed(dist, accel);
            let covered = |mut v: i64| {
                let mut sum = 0i128;
                while v > 0 {
                    sum += i128::from(v);
                    v -= accel;
                }
                sum
            };
            assert!(covered(v as i64) <= i128::from(dist), "{dist} {accel}");
            if dist < 1 << 21 {
                assert!(covered(v as i64 + 1) > i128::from(dist), "{dist} {accel}");
            }
        }
    }
}
