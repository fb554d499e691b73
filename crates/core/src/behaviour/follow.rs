//! Following one person's bearing: an alpha-beta filter per axis with a
//! still and a moving mode, so that a walker is followed with little lag
//! and a person standing still does not make the head twitch.
//!
//! Per sighting (about every 100 ms, times in ms, never in frames) each
//! axis' estimate `x` and rate `v` take the measured angle `z`:
//!
//! ```text
//! x⁻ = x + v·dt,   r = z − x⁻,   x = x⁻ + α·r,   v = v + β·r/dt
//! ```
//!
//! with `α = 0.35`, `β = 0.06`. An axis is *still* until its rate passes
//! [`MOVE`] or its estimate leaves the aim by more than [`BAND`]: radar
//! noise on a standing person (±40 mm at 2 m is ±1.1°) stays inside the
//! band after the filter, so the aim, and the head, do not move at all.
//! A *moving* axis aims where the person will be [`LEAD`] on, `x + v·LEAD`,
//! and the gaze glides there in [`GLIDE`] from wherever it is (a
//! minimum-jerk move from its position, speed and acceleration, planned
//! again at every sighting); it is still again once its rate has stayed
//! below [`STILL`] for [`SETTLE`]. The design notes give the figures these
//! were tuned on (`docs/design/attention.md`).

/// Rate above which a still axis moves, m°/s.
pub const MOVE: i32 = 8_000;
/// Rate below which a moving axis may come to rest, m°/s.
pub const STILL: i32 = 4_000;
/// How long the rate must stay below [`STILL`], ms.
pub const SETTLE: u32 = 500;
/// How far the estimate may leave a still aim, m°.
pub const BAND: i32 = 2_500;
/// How far ahead a moving aim looks, ms.
pub const LEAD: i32 = 200;
/// The duration of each following glide, ms.
pub const GLIDE: u32 = 300;
/// The longest and shortest time between two sightings the filter takes
/// as it is, ms (a longer gap counts as the longest).
const DT: (u32, u32) = (20, 500);

/// One axis' filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Axis {
    /// The estimate and the aim, m°; the rate, m°/s.
    x: i32,
    v: i32,
    aim: i32,
    moving: bool,
    /// How long the rate has been below [`STILL`], ms.
    calm: u32,
}

impl Axis {
    /// At `z`, still, aiming there.
    pub(crate) const fn at(z: i32) -> Self {
        Self {
            x: z,
            v: 0,
            aim: z,
            moving: false,
            calm: 0,
        }
    }

    /// The aim, m°.
    pub(crate) const fn aim(&self) -> i32 {
        self.aim
    }

    /// The measured angle `z` after `dt_ms`; whether the aim moved.
    pub(crate) fn update(&mut self, z: i32, dt_ms: u32) -> bool {
        let dt = dt_ms.clamp(DT.0, DT.1) as i32;
        // |v| ≤ 2²⁰ m°/s (kept so below): v·dt fits.
        let predicted = self.x.saturating_add(self.v * dt / 1000);
        let r = z.saturating_sub(predicted).clamp(-360_000, 360_000);
        self.x = predicted.saturating_add(r * 7 / 20);
        self.v = self
            .v
            .saturating_add(r.saturating_mul(60) / dt)
            .clamp(-(1 << 20), 1 << 20);
        if !self.moving && (self.v.abs() > MOVE || self.x.abs_diff(self.aim) > BAND as u32) {
            self.moving = true;
            self.calm = 0;
        }
        if !self.moving {
            return false;
        }
        self.aim = self.x.saturating_add(self.v * LEAD / 1000);
        if self.v.abs() < STILL {
            self.calm = self.calm.saturating_add(dt as u32);
            if self.calm >= SETTLE {
                self.moving = false;
            }
        } else {
            self.calm = 0;
        }
        true
    }
}

/// Both axes of the gaze, `[pitch, yaw]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Follow {
    pub(crate) axes: [Axis; 2],
}

impl Follow {
    /// At `[pitch, yaw]`, still.
    pub(crate) const fn at(z: [i32; 2]) -> Self {
        Self {
            axes: [Axis::at(z[0]), Axis::at(z[1])],
        }
    }

    /// The aims, `[pitch, yaw]`, m°.
    pub(crate) const fn aims(&self) -> [i32; 2] {
        [self.axes[0].aim(), self.axes[1].aim()]
    }

    /// New measurements after `dt_ms`; whether either aim moved.
    pub(crate) fn update(&mut self, z: [i32; 2], dt_ms: u32) -> bool {
        let [p, y] = &mut self.axes;
        let pitch = p.update(z[0], dt_ms);
        let yaw = y.update(z[1], dt_ms);
        pitch | yaw
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_inside_the_band_never_moves_the_aim() {
        let mut axis = Axis::at(0);
        // ±1.15° alternating, the worst a filter sees from ±40 mm at 2 m.
        for k in 0..600 {
            let z = if k % 2 == 0 { 1150 } else { -1150 };
            assert!(!axis.update(z, 100), "moved at {k}");
        }
        assert_eq!(axis.aim(), 0);
    }

    #[test]
    fn a_steady_turn_is_followed_without_lag() {
        let mut axis = Axis::at(0);
        // 28.6 °/s: 1 m/s across at 2 m.
        for k in 1..=30 {
            axis.update(2860 * k, 100);
        }
        // The aim leads the last measurement by about LEAD.
        let lead = axis.aim() - 2860 * 30;
        assert!((4000..7000).contains(&lead), "{lead}");
        // Stopped: the axis comes to rest at the person.
        for _ in 0..30 {
            axis.update(2860 * 30, 100);
        }
        assert!(!axis.moving);
        assert!((axis.aim() - 2860 * 30).abs() < 1500, "{}", axis.aim());
    }
}
