//! Rest and wake: the head settles into a rest pose when nobody is there,
//! and comes back to life when someone comes.
//!
//! The rest layer's weight glides from 0 (awake) to 1 (at the rest pose)
//! and back along a minimum-jerk move, under the idle limits; a rest may
//! relax (no pulses) once there, and a wake may glance towards who woke it.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Rest and wake”).

use crate::command::{Hold, LookRequest};
use crate::units::{Angle, Millis};

use super::fixed::{ONE, ahead, mul_signed};
use super::glide::{Glide, State};
use super::params::{BehaviourParams, LimitMode};

/// The shortest rest: a calm settling into the pose.
pub const REST_TIME: Millis = Millis(3000);

/// The shortest wake: the idle is back within about a second.
pub const WAKE_TIME: Millis = Millis(1000);

/// How long a glance holds before it returns.
pub const GLANCE_HOLD: Millis = Millis(2000);

/// What the idle may add to the distance while the blend plays, m°.
pub const DRIFT: u32 = 5000;

/// The idle's own speed, °/s, left free in the speed limit (the idle moves
/// at most about 8 °/s).
pub const IDLE_SPEED: u32 = 10;

/// Where the head is in resting.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RestState {
    /// Not resting: the blend is off.
    #[default]
    Awake,
    /// Gliding into the rest pose, or there.
    Resting,
    /// Gliding out of it: the idle fades back in.
    Waking,
}

/// The rest layer; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Rest {
    state: RestState,
    /// The pose's weight, Q16.
    weight: Glide,
    /// The pose's offsets `[pitch, roll, yaw]`, m°.
    pose: [Glide; 3],
    /// The base (idle and gaze, before the blend) of the last frame mixed
    /// while resting or waking, m°.
    base: [i32; 3],
    /// Arrived at the pose (resting, nothing moving).
    arrived: bool,
    /// The glance to make once awake: its yaw (an axis angle).
    glance: Option<Angle>,
}

impl Rest {
    /// Awake.
    pub(crate) const fn new() -> Self {
        Self {
            state: RestState::Awake,
            weight: Glide::rest(0),
            pose: [Glide::rest(0); 3],
            base: [0; 3],
            arrived: false,
            glance: None,
        }
    }

    /// Where the head is in resting.
    pub(crate) const fn state(&self) -> RestState {
        self.state
    }

    /// Whether the blend is on (resting or waking).
    #[inline]
    pub(crate) const fn active(&self) -> bool {
        !matches!(self.state, RestState::Awake)
    }

    /// Whether the head rests at its pose, nothing moving.
    pub(crate) const fn arrived(&self) -> bool {
        self.arrived
    }

    /// Starts (or redirects) a rest at time `next` towards `pose`
    /// (offsets around the neutral pose), from the head at `at` (the
    /// offsets of the last frame, when awake); returns its duration.
    pub(crate) fn rest(
        &mut self,
        params: &BehaviourParams,
        next: u32,
        pose: [i32; 3],
        at: [i32; 3],
    ) -> Millis {
        let weight = self.weight.state(next);
        let resting = self.state == RestState::Resting && self.weight.target() == ONE as i32;
        if resting && self.pose.iter().zip(pose).all(|(g, p)| g.target() == p) {
            // There already (0), or on the way.
            let left = self.next_event(next);
            return BehaviourParams::millis(if left == u32::MAX { 0 } else { left });
        }
        let us = if self.active() {
            // The pose glides to the new one as the weight goes on rising
            // (or turns round): each part fits the limits on its own.
            let from: [State; 3] = core::array::from_fn(|i| self.pose[i].state(next));
            let shift = far(from.map(|s| s.pos), pose, 0);
            let us = fit(params, REST_TIME, shift.max(far(pose, self.base, DRIFT)));
            self.pose = core::array::from_fn(|i| Glide::new(next, from[i], pose[i], us));
            us
        } else {
            // The blend starts from the head as it is.
            self.base = at;
            self.pose = pose.map(Glide::rest);
            fit(params, REST_TIME, far(pose, at, DRIFT))
        };
        self.weight = Glide::new(next, weight, ONE as i32, us);
        self.state = RestState::Resting;
        self.arrived = false;
        BehaviourParams::millis(us)
    }

    /// Starts a wake at time `next` (if resting); once awake the head
    /// glances towards `glance`, if given. Returns the wake's duration
    /// (`None` if the head was awake).
    pub(crate) fn wake(
        &mut self,
        params: &BehaviourParams,
        next: u32,
        glance: Option<Angle>,
    ) -> Option<Millis> {
        if !self.active() {
            return None;
        }
        if glance.is_some() {
            self.glance = glance;
        }
        if self.state == RestState::Waking {
            return Some(BehaviourParams::millis(
                self.weight.end().wrapping_sub(next),
            ));
        }
        let pose = self.pose.map(|g| g.target());
        let us = fit(params, WAKE_TIME, far(pose, self.base, DRIFT));
        self.weight = Glide::new(next, self.weight.state(next), 0, us);
        self.state = RestState::Waking;
        self.arrived = false;
        Some(BehaviourParams::millis(us))
    }

    /// The offsets at time `now` over `base` (idle and gaze): the blend. (Out
    /// of line: it plays only while resting or waking, and the frames of a
    /// head awake should not carry its registers.)
    #[inline(never)]
    pub(crate) fn blend(&mut self, now: u32, base: [i32; 3]) -> [i32; 3] {
        self.base = base;
        let w = value(&mut self.weight, now);
        let [pitch, roll, yaw] = &mut self.pose;
        let pose = [value(pitch, now), value(roll, now), value(yaw, now)];
        if w >= ONE as i32 {
            return pose;
        }
        // A glide that starts moving may overshoot its ends a little.
        let w = w.clamp(0, ONE as i32);
        // Within the limits: the differences fit.
        core::array::from_fn(|i| base[i] + mul_signed(pose[i] - base[i], w))
    }

    /// At a frame mixed in full: the state after it. Returns the
    /// glance to start, once a wake has ended.
    pub(crate) fn settle(&mut self) -> Option<Angle> {
        let moving = self.weight.moving() || self.pose.iter().any(Glide::moving);
        match self.state {
            RestState::Resting => {
                self.arrived = !moving;
                None
            }
            RestState::Waking if !self.weight.moving() => {
                self.state = RestState::Awake;
                self.glance.take()
            }
            _ => None,
        }
    }

    /// µs from `from` to the next time after it at which a glide of the
    /// blend ends (`u32::MAX`: none).
    pub(crate) fn next_event(&self, from: u32) -> u32 {
        let mut soonest = u32::MAX;
        if self.weight.moving() {
            soonest = soonest.min(ahead(self.weight.end(), from));
        }
        for pose in &self.pose {
            if pose.moving() {
                soonest = soonest.min(ahead(pose.end(), from));
            }
        }
        soonest
    }
}

/// A glide's value at `now`, out of line: the blend's four glides share
/// one copy of the code (they play only while resting or waking).
#[inline(never)]
fn value(glide: &mut Glide, now: u32) -> i32 {
    glide.at(now)
}

/// The glance towards `yaw`: level, held [`GLANCE_HOLD`], then back.
pub(crate) fn glance(params: &BehaviourParams, yaw: Angle) -> LookRequest {
    LookRequest {
        pitch: params.neutral_pose()[0],
        yaw,
        duration: None,
        hold: Some(Hold::Return(GLANCE_HOLD)),
    }
}

/// The largest distance between `a` and `b` over the axes, plus `extra`, m°.
fn far(a: [i32; 3], b: [i32; 3], extra: u32) -> u32 {
    let d = a
        .iter()
        .zip(&b)
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap_or(0);
    d.saturating_add(extra)
}

/// µs of a blend over `distance` m°: at least `least`, and long enough for
/// the idle limits of every axis (see the [module docs](self#how-long)).
fn fit(params: &BehaviourParams, least: Millis, distance: u32) -> u32 {
    let mut us = 2;
    for axis in crate::axis::Axis::ALL {
        let limits = params.limits(axis, LimitMode::Idle);
        let speed = limits.max_speed.0.saturating_sub(IDLE_SPEED);
        let fit = BehaviourParams::move_us(least.0.into(), distance, speed, limits.max_accel.0 / 2);
        us = us.max(fit);
    }
    us
}
