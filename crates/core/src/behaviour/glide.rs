//! Minimum-jerk moves that start from any state: the gaze's centre and the
//! idle gain.
//!
//! From rest, a move of distance `D` over `T` is the minimum-jerk profile
//! `p(τ) = p₀ + D·(10τ³ − 15τ⁴ + 6τ⁵)`, `τ = t/T`. A new move that starts
//! while another one plays starts from where the value is *and* from its
//! velocity and acceleration, so neither jumps: the quintic with those ends
//! (position `p₀`, velocity `v`, acceleration `a` at `τ = 0`, in units of the
//! move: `v = dp/dτ`, `a = d²p/dτ²`; the target at rest at `τ = 1`), which
//! is the minimum-jerk path between those states.
//!
//! Written around the target, with `s = 1 − τ`, it reads
//!
//! ```text
//! p = target − s³·(r₀ + r₁·s + r₂·s²)
//! r₀ = 10D − 4v − a/2,   r₁ = −15D + 7v + a,   r₂ = 6D − 3v − a/2
//! ```
//!
//! (at `s = 1`: `r₀ + r₁ + r₂ = D`, `h′ = 3r₀ + 4r₁ + 5r₂ = v`,
//! `−h″ = −(6r₀ + 12r₁ + 20r₂) = a`; from rest this is the profile above).
//! Times are µs on the frame path's clock (see `fixed.rs`), so a glide
//! moves the same in time whatever the frame rate. Per frame: `s` in Q16
//! from a precomputed reciprocal ([`Span`]) and five rounded Q16 multiplies
//! (Horner for the quadratic, then `· s` three times): within 2.5 m° of the
//! polynomial whatever the distance, and the start and the end are exact.

use super::fixed::{ONE, Span, mul};

/// Where a value is and how it moves, at one time: the position and the
/// first two derivatives in units of the move it comes from (`dp/dτ`,
/// `d²p/dτ²` over that move's `len` µs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct State {
    /// The value (as the frame path computes it).
    pub(crate) pos: i32,
    slope: i64,
    curve: i64,
    len: u32,
}

impl State {
    /// At rest at `pos`.
    pub(crate) const fn rest(pos: i32) -> Self {
        Self {
            pos,
            slope: 0,
            curve: 0,
            len: 1,
        }
    }
}

/// Bound of the coefficients: sums of two stay inside `i32`.
const BOUND: i64 = 1 << 29;
/// Velocities and accelerations beyond this give coefficients past the bound.
const FAR: i64 = 1 << 40;

/// One value moving to a target; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Glide {
    /// Time of `τ = 0`, µs.
    pub(crate) start: u32,
    /// `T`; of length 0 once arrived.
    span: Span,
    target: i32,
    r: [i32; 3],
}

impl Glide {
    /// At rest at `value`.
    pub(crate) const fn rest(value: i32) -> Self {
        Self {
            start: 0,
            span: Span::ENDED,
            target: value,
            r: [0; 3],
        }
    }

    /// A move from `from` at time `start` to `target`, arriving `len` µs
    /// later (within `2..=MAX_SPAN`).
    pub(crate) fn new(start: u32, from: State, target: i32, len: u32) -> Self {
        let span = Span::new(len);
        let (len, old) = (i64::from(span.len()), i64::from(from.len.max(1)));
        let dist = i64::from(target) - i64::from(from.pos);
        // Velocity and acceleration in units of this move (saturating: a
        // coefficient past the bound is clamped anyway).
        let vel = from.slope.saturating_mul(len) / old;
        let acc = (from.curve.saturating_mul(len) / old).saturating_mul(len) / old;
        // Far past the bound either way; below it the sums stay exact.
        let (vel, acc) = (vel.clamp(-FAR, FAR), acc.clamp(-FAR, FAR));
        let r = [
            10 * dist - 4 * vel - acc / 2,
            -15 * dist + 7 * vel + acc,
            6 * dist - 3 * vel - acc / 2,
        ]
        .map(|c| c.clamp(-BOUND, BOUND) as i32);
        Self {
            start,
            span,
            target,
            r,
        }
    }

    /// A glide on this one's clock that falls from `from`, at rest, to 0:
    /// the profile of a move from rest, `r = −from·(10, −15, 6)`, no
    /// division (the reciprocal is this glide's).
    pub(crate) fn falling(&self, from: i32) -> Self {
        let d = -i64::from(from);
        let r = |k: i64| (k * d).clamp(-BOUND, BOUND) as i32;
        Self {
            start: self.start,
            span: self.span,
            target: 0,
            r: [r(10), r(-15), r(6)],
        }
    }

    /// The target.
    pub(crate) const fn target(&self) -> i32 {
        self.target
    }

    /// The time the move arrives at (meaningful while [`moving`](Self::moving)).
    pub(crate) const fn end(&self) -> u32 {
        self.start.wrapping_add(self.span.len())
    }

    /// Whether the move is still under way (as of the last [`at`](Self::at)).
    pub(crate) const fn moving(&self) -> bool {
        self.span.len() != 0
    }

    /// The value at time `now` (not before `start`). Once arrived the glide
    /// rests at its target for good.
    #[inline]
    pub(crate) fn at(&mut self, now: u32) -> i32 {
        let t = now.wrapping_sub(self.start);
        if t >= self.span.len() {
            self.span = Span::ENDED;
            return self.target;
        }
        let [r0, r1, r2] = self.r;
        if t == 0 {
            return self.target - (r0 + r1 + r2);
        }
        // 0 < t < T: 0 < s ≤ 1 (s = 1 only for t below the span's unit).
        self.at_s(ONE - self.span.progress(t))
    }

    /// The values of three glides on one clock (the same start and
    /// duration, as the gaze's axes and its envelope always are) at time
    /// `now`, each as [`at`](Self::at) gives it: `s` is worked out once,
    /// and a third glide that holds its value (the gaze's envelope from
    /// one look to the next) costs nothing.
    #[inline]
    pub(crate) fn trio_at(trio: &mut [Self; 3], now: u32) -> [i32; 3] {
        let [one, two, three] = trio;
        debug_assert!(
            one.start == three.start && one.span == three.span,
            "not on one clock"
        );
        if one.start != two.start || one.span != two.span {
            return [one.at(now), two.at(now), three.at(now)];
        }
        let t = now.wrapping_sub(one.start);
        if t >= one.span.len() {
            (one.span, two.span, three.span) = (Span::ENDED, Span::ENDED, Span::ENDED);
            return [one.target, two.target, three.target];
        }
        if t == 0 {
            return [one.at(now), two.at(now), three.at(now)];
        }
        // The same span, the same reciprocal.
        let s = ONE - one.span.progress(t);
        let [r0, r1, r2] = three.r;
        let held = if r0 == 0 && r1 == 0 && r2 == 0 {
            three.target
        } else {
            three.at_s(s)
        };
        [one.at_s(s), two.at_s(s), held]
    }

    /// The value at `s = 1 − τ` (Q16, `0 < s ≤ 1`). Each multiply rounds to
    /// the unit: the value is within 2.5 units of the exact polynomial at
    /// this `s`.
    #[inline]
    fn at_s(&self, s: u32) -> i32 {
        let [r0, r1, r2] = self.r;
        let q = mul(mul(r2, s) + r1, s) + r0;
        self.target - mul(mul(mul(q, s), s), s)
    }

    /// The state at time `now`: the position exactly as [`at`](Self::at)
    /// gives it, velocity and acceleration from the derivatives (for a new
    /// move to start from).
    pub(crate) fn state(&self, now: u32) -> State {
        let mut copy = *self;
        let pos = copy.at(now);
        let t = now.wrapping_sub(self.start);
        if t >= self.span.len() {
            return State::rest(pos);
        }
        let s = i64::from(ONE - self.span.progress(t));
        let [r0, r1, r2] = self.r.map(i64::from);
        // Horner in Q16 steps (|r| ≤ 2²⁹: every product below 2⁵²):
        // h′(s) = s²·(3r₀ + s·(4r₁ + s·5r₂)), h″(s) = s·(6r₀ + s·(12r₁ + s·20r₂)).
        let q = |x: i64| (x * s) >> 16;
        let slope = q(q(3 * r0 + q(4 * r1 + q(5 * r2))));
        let curve = -q(6 * r0 + q(12 * r1 + q(20 * r2)));
        State {
            pos,
            slope,
            curve,
            len: self.span.len(),
        }
    }
}
