//! Gaze: where the head's centre is (pitch and yaw), moved by `look` and
//! `center` along minimum-jerk glides ([`super::glide`]).
//!
//! A move takes `base + per_degree · d` unless a duration is given, and is
//! lengthened until it fits the axes' gesture limits; a target outside the
//! limits is clamped (and the answer says so); after its hold the head
//! returns to the centre, or stays (`hold=stay`). The look's envelope
//! ducks the idle on pitch and yaw while the look holds.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Gaze”).

use crate::axis::Axis;
use crate::command::{Hold, LookRequest};
use crate::units::{Angle, Millis};

use super::config::MAX_HOLD;
use super::error::BehaviourError;
use super::fixed::{ONE, ahead};
use super::glide::{Glide, State};
use super::params::{BehaviourParams, LimitMode};

/// The axes a look moves, in `Gaze`'s order.
pub(crate) const AXES: [Axis; 2] = [Axis::Pitch, Axis::Yaw];

/// What a look did.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LookApplied {
    /// The target pitch, after clamping.
    pub pitch: Angle,
    /// The target yaw, after clamping.
    pub yaw: Angle,
    /// Whether the target was clamped to the limits.
    pub clamped: bool,
    /// The move's duration.
    pub duration: Millis,
    /// What the head does once there.
    pub hold: Hold,
}

/// The gaze's centre: a glide per axis and the envelope (see the [module
/// docs](self#the-looks-envelope)), and, maybe, the return planned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Gaze {
    /// `[pitch, yaw, envelope]`, on one clock.
    axes: [Glide; 3],
    /// The planned return.
    back: Option<Back>,
    /// What moved the gaze last.
    by: By,
}

/// What moved the gaze last: a tracker follows only a gaze that a look
/// does not hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum By {
    /// `center`, a rest, or a look's return under way: the centre.
    Centre,
    /// A look, until its return starts.
    Look,
    /// The tracker.
    Track,
}

/// A planned return: `[pitch, yaw]` back to the centre (the envelope
/// falls along it), starting `wait` µs after `from`. (Kept as a wait, not
/// a time: a hold may last up to an hour, longer than the clock's half
/// round, and the wait is compared unsigned.)
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Back {
    glides: [Glide; 2],
    from: u32,
    wait: u32,
}

impl Back {
    /// Whether the return starts at or before `now`.
    const fn due(&self, now: u32) -> bool {
        now.wrapping_sub(self.from) >= self.wait
    }
}

impl Gaze {
    /// At the centre, at rest.
    pub(crate) const fn new() -> Self {
        Self {
            axes: [Glide::rest(0); 3],
            back: None,
            by: By::Centre,
        }
    }

    /// The centre's offsets (m°) and the look's envelope (Q16) at time
    /// `now`: `[pitch, yaw, envelope]`. (A move that starts while another
    /// plays may overshoot its ends a little: the envelope may pass 0 or 1
    /// by a few counts.)
    #[inline]
    pub(crate) fn at(&mut self, now: u32) -> [i32; 3] {
        if self.returns_by(now)
            && let Some(Back {
                glides: [pitch, yaw],
                ..
            }) = self.back.take()
        {
            let envelope = pitch.falling(ONE as i32);
            self.axes = [pitch, yaw, envelope];
            self.by = By::Centre;
        }
        Glide::trio_at(&mut self.axes, now)
    }

    /// Whether the gaze rests at the centre, nothing planned (as of the
    /// last `at`).
    pub(crate) fn centred(&self) -> bool {
        self.back.is_none() && self.axes.iter().all(|g| !g.moving() && g.target() == 0)
    }

    /// Whether the planned return starts at or before time `now`.
    pub(crate) fn returns_by(&self, now: u32) -> bool {
        self.back.as_ref().is_some_and(|back| back.due(now))
    }

    /// µs from `from` to the next time after it at which a move ends, the
    /// planned return is due next frame, or it starts (`u32::MAX`: none).
    /// A return due at `from` or before counts as 1 µs on (a move then
    /// starts whose end is not known yet).
    pub(crate) fn next_event(&self, from: u32, period: u32) -> u32 {
        let mut soonest = u32::MAX;
        // (The envelope ends with the axes.)
        for axis in &self.axes[..2] {
            if axis.moving() {
                soonest = soonest.min(ahead(axis.end(), from));
            }
        }
        if let Some(back) = &self.back {
            // Due next frame: one period before it starts.
            let start = if back.due(from) {
                0
            } else {
                back.wait - from.wrapping_sub(back.from)
            };
            soonest = soonest.min(start.saturating_sub(period).max(1));
        }
        soonest
    }

    /// Whether a return is planned.
    pub(crate) const fn pending(&self) -> bool {
        self.back.is_some()
    }

    /// Whether each axis `[pitch, yaw]` is moving (as of the last `at`;
    /// the envelope moves with them).
    pub(crate) const fn moving(&self) -> [bool; 2] {
        [self.axes[0].moving(), self.axes[1].moving()]
    }

    /// Starts a look at time `next`.
    pub(crate) fn look(
        &mut self,
        params: &BehaviourParams,
        next: u32,
        request: &LookRequest,
    ) -> Result<LookApplied, BehaviourError> {
        let hold = request.hold.unwrap_or(params.config().gaze.hold);
        if let Hold::Return(ms) = hold
            && ms > MAX_HOLD
        {
            return Err(BehaviourError::Duration {
                field: "look hold",
                duration: ms,
                min: Millis(0),
                max: MAX_HOLD,
            });
        }
        check_duration(params, "look duration", request.duration)?;
        let pose = params.neutral_pose();
        let mut clamped = false;
        let targets = [request.pitch, request.yaw];
        let offsets: [i32; 2] = core::array::from_fn(|i| {
            let (inside, outside) = params.offset_within(AXES[i], targets[i]);
            clamped |= outside;
            inside.millidegrees()
        });
        let us = self.move_to(params, next, offsets, ONE as i32, request.duration);
        self.by = By::Look;
        self.back = match hold {
            Hold::Stay => None,
            Hold::Return(ms) => {
                // Within an hour and 10 s: no wrap of the unsigned wait.
                let wait = us.saturating_add(BehaviourParams::micros(ms).max(1));
                let at = next.wrapping_add(wait);
                let back_us = duration(params, offsets.map(i32::unsigned_abs), None);
                Some(Back {
                    glides: offsets.map(|o| Glide::new(at, State::rest(o), 0, back_us)),
                    from: next,
                    wait,
                })
            }
        };
        let absolute =
            |i: usize| Angle::from_millidegrees(offsets[i]).saturating_add(pose[AXES[i].index()]);
        Ok(LookApplied {
            pitch: absolute(0),
            yaw: absolute(1),
            clamped,
            duration: BehaviourParams::millis(us),
            hold,
        })
    }

    /// Starts a move back to the centre at time `next`; returns its duration.
    pub(crate) fn center(
        &mut self,
        params: &BehaviourParams,
        next: u32,
        given: Option<Millis>,
    ) -> Result<Millis, BehaviourError> {
        check_duration(params, "center duration", given)?;
        let us = self.move_to(params, next, [0, 0], 0, given);
        self.back = None;
        self.by = By::Centre;
        Ok(BehaviourParams::millis(us))
    }

    /// What moved the gaze last.
    pub(crate) const fn by(&self) -> By {
        self.by
    }

    /// The tracker's move at time `next` to `offsets` (m° around the
    /// neutral pose, within the axes' room), in `given` or the rule's
    /// time (lengthened to fit the gesture limits), the idle ducked as
    /// under a held look; returns its duration in µs.
    pub(crate) fn follow(
        &mut self,
        params: &BehaviourParams,
        next: u32,
        offsets: [i32; 2],
        given: Option<Millis>,
    ) -> u32 {
        let us = self.move_to(params, next, offsets, ONE as i32, given);
        self.back = None;
        self.by = By::Track;
        us
    }

    /// Glides both axes from where they are at `next` to `offsets`, and the
    /// envelope to `envelope`; returns the duration in µs.
    fn move_to(
        &mut self,
        params: &BehaviourParams,
        next: u32,
        offsets: [i32; 2],
        envelope: i32,
        given: Option<Millis>,
    ) -> u32 {
        // A return that was due by `next` is under way: start from it.
        let _ = self.at(next);
        let from = self.axes.map(|g| g.state(next));
        let distance: [u32; 2] = core::array::from_fn(|i| offsets[i].abs_diff(from[i].pos));
        let us = duration(params, distance, given);
        let [pitch, yaw] = offsets;
        let to = [pitch, yaw, envelope];
        self.axes = core::array::from_fn(|i| Glide::new(next, from[i], to[i], us));
        us
    }
}

/// A given duration must lie in `1..=gaze.longest`.
fn check_duration(
    params: &BehaviourParams,
    field: &'static str,
    given: Option<Millis>,
) -> Result<(), BehaviourError> {
    let longest = params.config().gaze.longest;
    match given {
        Some(ms) if ms.0 == 0 || ms > longest => Err(BehaviourError::Duration {
            field,
            duration: ms,
            min: Millis(1),
            max: longest,
        }),
        _ => Ok(()),
    }
}

/// µs of a move of `distance` (m°, `[pitch, yaw]`): the given duration or
/// the rule's, lengthened until it fits the gesture limits.
fn duration(params: &BehaviourParams, distance: [u32; 2], given: Option<Millis>) -> u32 {
    let gaze = params.config().gaze;
    let far = u64::from(distance[0].max(distance[1]));
    let ms = match given {
        Some(ms) => u64::from(ms.0),
        None => u64::from(gaze.base.0) + (u64::from(gaze.per_degree.0) * far).div_ceil(1000),
    };
    let mut us = 2;
    for (axis, d) in AXES.iter().zip(distance) {
        let limits = params.limits(*axis, LimitMode::Gesture);
        let fit = BehaviourParams::move_us(ms, d, limits.max_speed.0, limits.max_accel.0);
        us = us.max(fit);
    }
    us
}
