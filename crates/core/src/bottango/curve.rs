//! Bottango's curves: a cubic Bézier of movement over time, evaluated in
//! integers.
//!
//! A curve runs from `(0, y₀)` to `(T, y₃)`, its control points at
//! `(x₁, y₁)` and `(x₂, y₂)` (`sC` sends them relative to their ends). Time
//! is the x axis: at `t` ms after the start the movement is `y(u)` for the
//! `u` with `x(u) = t`. Here the control points' times are fractions of
//! `T` (Q15, clamped to `[0, 1]`, so `x(u)` runs from 0 to 1), `u` is found
//! by 15 bisection steps on `x(u)` (de Casteljau, 32-bit), then `y(u)`:
//! within one step of 2⁻¹⁵ of the exact `u`, a few movement units of 8192.

use super::line::CurveArgs;

/// Movement at full travel: `sC` and `sCI` send movements in `0..=8192`.
pub const FULL: i32 = 8192;

/// Q15: 1.0.
const ONE: i32 = 1 << 15;

/// Movements of the points are kept within two full travels around the
/// range (`-8192..=16384`): every difference then fits the 32-bit lerp.
const Y_MIN: i32 = -FULL;
const Y_MAX: i32 = 2 * FULL;

/// How long an instant target (`sCI`) holds as a curve of its own.
pub const INSTANT_HOLD_MS: u32 = 1000;

/// One curve in the head's clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Curve {
    /// Start, ms of the frame task's clock (wrapping).
    pub start: u32,
    /// Duration, ms.
    pub duration: u32,
    /// The control points' times, fractions of the duration (Q15).
    x: [u16; 2],
    /// Movements of the start, its control point, the end's control point
    /// and the end.
    y: [i16; 4],
}

impl Curve {
    /// No curve (a free slot).
    pub const EMPTY: Self = Self {
        start: 0,
        duration: 0,
        x: [0; 2],
        y: [0; 4],
    };

    /// The curve `args` describes, starting at `start` (the head's clock).
    #[must_use]
    pub fn new(start: u32, args: &CurveArgs) -> Self {
        let duration = args.duration;
        let fraction = |ms: i64| -> u16 {
            if duration == 0 {
                return 0;
            }
            let q = (ms.clamp(0, i64::from(duration)) << 15) / i64::from(duration);
            u16::try_from(q).unwrap_or(u16::MAX)
        };
        let y = |v: i64| v.clamp(i64::from(Y_MIN), i64::from(Y_MAX)) as i16;
        let (y0, y3) = (i64::from(args.start_y), i64::from(args.end_y));
        Self {
            start,
            duration,
            x: [
                fraction(i64::from(args.start_control.0)),
                fraction(i64::from(duration) + i64::from(args.end_control.0)),
            ],
            y: [
                y(y0),
                y(y0 + i64::from(args.start_control.1)),
                y(y3 + i64::from(args.end_control.1)),
                y(y3),
            ],
        }
    }

    /// `movement` held from `start` for [`INSTANT_HOLD_MS`]: an instant
    /// target.
    #[must_use]
    pub fn hold(start: u32, movement: i32) -> Self {
        let m = movement.clamp(Y_MIN, Y_MAX) as i16;
        Self {
            start,
            duration: INSTANT_HOLD_MS,
            x: [0, ONE as u16],
            y: [m; 4],
        }
    }

    /// When it ends (the head's clock, wrapping).
    #[must_use]
    pub const fn end(&self) -> u32 {
        self.start.wrapping_add(self.duration)
    }

    /// The movement at the end.
    #[must_use]
    pub const fn end_movement(&self) -> i32 {
        self.y[3] as i32
    }

    /// The movement `t` ms after the start (the end's at and after it).
    #[must_use]
    pub fn at(&self, t: u32) -> i32 {
        let [y0, y1, y2, y3] = self.y.map(i32::from);
        if t >= self.duration {
            return y3;
        }
        if t == 0 {
            return y0;
        }
        // 0 < t < T: 0 < τ < 1 (Q15).
        let tau = ((u64::from(t) << 15) / u64::from(self.duration.max(1))) as i32;
        let [x1, x2] = self.x.map(i32::from);
        let (mut lo, mut hi): (i32, i32) = (0, ONE);
        for _ in 0..15 {
            let mid = lo.midpoint(hi);
            if bezier(0, x1, x2, ONE, mid) < tau {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        bezier(y0, y1, y2, y3, lo.midpoint(hi))
    }
}

/// `a + (b − a)·u` for `u` in Q15 (`|b − a| ≤ 24 576`: the product fits `i32`).
const fn lerp(a: i32, b: i32, u: i32) -> i32 {
    a + (((b - a) * u) >> 15)
}

/// The cubic Bézier of `p` at `u` (Q15), by de Casteljau's construction.
const fn bezier(p0: i32, p1: i32, p2: i32, p3: i32, u: i32) -> i32 {
    let (q0, q1, q2) = (lerp(p0, p1, u), lerp(p1, p2, u), lerp(p2, p3, u));
    let (r0, r1) = (lerp(q0, q1, u), lerp(q1, q2, u));
    lerp(r0, r1, u)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(duration: u32, ys: (i32, i32), controls: ((i32, i32), (i32, i32))) -> Curve {
        Curve::new(
            1000,
            &CurveArgs {
                start: 0,
                duration,
                start_y: ys.0,
                start_control: controls.0,
                end_y: ys.1,
                end_control: controls.1,
            },
        )
    }

    /// The exact curve at `t`, in floats, as Bottango's float driver
    /// evaluates it: `u` with `x(u) = t` by bisection to 1e-9, then `y(u)`.
    fn reference(duration: f64, p: [(f64, f64); 4], t: f64) -> f64 {
        let b = |a: f64, b: f64, c: f64, d: f64, u: f64| {
            let v = 1.0 - u;
            v * v * v * a + 3.0 * v * v * u * b + 3.0 * v * u * u * c + u * u * u * d
        };
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..60 {
            let mid = f64::midpoint(lo, hi);
            if b(p[0].0, p[1].0, p[2].0, p[3].0, mid) < t {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let _ = duration;
        b(p[0].1, p[1].1, p[2].1, p[3].1, lo)
    }

    #[test]
    fn ends_are_exact_and_the_inside_follows_the_float_curve() {
        let cases = [
            (1000, (0, 8192), ((250, 0), (-250, 0))),
            (1000, (8192, 0), ((0, 0), (0, 0))),
            (3000, (1000, 7000), ((1500, 3000), (-100, -2000))),
            (40, (4096, 4100), ((10, 8000), (-10, -8000))),
            (600_000, (0, 8192), ((300_000, 0), (-300_000, 0))),
        ];
        for (duration, ys, controls) in cases {
            let c = curve(duration, ys, controls);
            assert_eq!(c.at(0), ys.0);
            assert_eq!(c.at(duration), ys.1);
            assert_eq!(c.at(duration + 5), ys.1);
            let d = f64::from(duration);
            let p = [
                (0.0, f64::from(ys.0)),
                (f64::from(controls.0.0), f64::from(ys.0 + controls.0.1)),
                (d + f64::from(controls.1.0), f64::from(ys.1 + controls.1.1)),
                (d, f64::from(ys.1)),
            ];
            for k in 1..100 {
                let t = duration * k / 100;
                let want = reference(d, p, f64::from(t));
                let got = c.at(t);
                assert!(
                    (f64::from(got) - want).abs() <= 6.0,
                    "T={duration} t={t}: {got} vs {want:.1}"
                );
            }
        }
    }

    #[test]
    fn a_hold_is_flat() {
        let c = Curve::hold(7, 5000);
        assert_eq!((c.at(0), c.at(500), c.at(2000)), (5000, 5000, 5000));
        assert_eq!(c.end(), 7 + INSTANT_HOLD_MS);
    }

    #[test]
    fn wild_control_points_stay_bounded() {
        let c = curve(100, (0, 8192), ((-5000, 90_000), (5000, -90_000)));
        for t in 0..=100 {
            assert!((Y_MIN..=Y_MAX).contains(&c.at(t)));
        }
    }
}
