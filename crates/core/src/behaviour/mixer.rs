//! The one place where the layers meet.
//!
//! Per axis and frame:
//!
//! ```text
//! base   = centre + idle · gain · Π(1 − duck·Eᵢ) · (1 − look_duck·E_look)
//! offset = base + w · (pose − base) + Σ gestureᵢ
//! ```
//!
//! (gaze, the idle ducked under the gestures and the look, the rest layer,
//! up to [`LAYERS`] gesture layers, an older one fading out under a new one:
//! never a jump). Times are µs on the frame path's clock. The mixer also
//! says which limit mode each axis needs ([`Mixer::modes`]).
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The mixer”).

use crate::command::{Action, LookRequest, Percent};
use crate::units::{Angle, AngleRange, Microseconds, Millis, Timestamp};

use super::rest::RestState;

use super::error::BehaviourError;
use super::fixed::{ONE, ahead, mul};
use super::gaze::{Gaze, LookApplied};
use super::gesture::GesturePlan;
use super::glide::Glide;
use super::params::{BehaviourParams, LimitMode, q16};
use super::rest::{self, Rest};

mod layers;
mod math;
mod tracking;

use layers::Layer;
use math::{Countdown, both, idle_part, look_keep};

/// Gesture layers: one playing and up to two fading out under it.
pub const LAYERS: usize = 3;

/// What an action did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Applied {
    /// A gesture started, as resolved.
    Gesture(GesturePlan),
    /// A look started.
    Look(LookApplied),
    /// The move back to the centre started; it takes this long.
    Center(Millis),
    /// The idle gain glides to this.
    Idle(Percent),
    /// Stop: the driver fades everything out (not the mixer's to do).
    Stop,
    /// The head glides to its rest pose; it takes this long.
    Rest(Millis),
    /// The head wakes; the idle is back after this long (0: it was awake).
    Wake(Millis),
}

impl BehaviourParams {
    /// Checks `action` as [`Mixer::apply`] would on a
    /// head at rest: every check but the ones that depend on what plays
    /// ([`BehaviourError::Busy`]). For replies before an action is queued:
    /// what the mixer would start, such as where a look goes and whether
    /// its target was clamped.
    ///
    /// # Errors
    /// The [`BehaviourError`] the mixer would answer.
    pub fn check(&self, action: &Action) -> Result<Applied, BehaviourError> {
        Mixer::new(*self).apply(action)
    }
}

/// Idle, gestures and gaze mixed into one set of offsets; see the
/// [module docs](self).
///
/// ```
/// use idle_head_core::behaviour::{BehaviourConfig, Mixer};
/// use idle_head_core::command::{Action, GestureKind, GestureRequest};
/// use idle_head_core::driver::DriverConfig;
/// use idle_head_core::{Angle, Timestamp};
///
/// let driver = DriverConfig::DEFAULT.build().unwrap();
/// let mut mixer = Mixer::new(BehaviourConfig::DEFAULT.build(&driver).unwrap());
/// mixer.apply(&Action::Gesture(GestureRequest::new(GestureKind::Nod))).unwrap();
/// // The default nod: 2 cycles at 2.5 Hz in 800 ms; its first dip peaks at 200 ms
/// // (frame 10 at 50 Hz) at 6.3° (6° × 1.05: a default amplitude rises with the
/// // number of cycles).
/// let frame = |k: u64| Timestamp(k * 20_000);
/// let pitch: Vec<i32> = (0..45)
///     .map(|k| mixer.frame(frame(k), [Angle::ZERO; 3])[0].millidegrees())
///     .collect();
/// assert_eq!(pitch[0], 0);
/// assert_eq!(pitch[10], 6300);
/// assert_eq!(pitch[40], 0);
/// ```
///
/// The fields are laid out in the order written (`repr(C)`), those every
/// frame reads first: on ARMv6-M a load reaches 124 bytes past a pointer,
/// and a field further on costs an instruction or two more to address.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct Mixer {
    /// The time of the last frame mixed, and of the next frame (at which
    /// actions start), µs.
    now: u32,
    next: u32,
    /// The frame period, µs (the parameters'), kept where it is cheap to
    /// reach.
    period: u32,
    /// The first time that must be mixed in full: nothing but the values
    /// changes before it (no layer or move starts or ends, no return is
    /// due, no settle time runs out).
    until: u32,
    /// Nothing moves but the idle, at `quiet_gain` (per axis) around
    /// `quiet_centre`; `quiet_unity` if every gain is 1.
    quiet: bool,
    quiet_unity: bool,
    /// The rest layer is on: [`Rest::active`], kept here where the frame
    /// path reaches it cheaply.
    resting: bool,
    /// A wake has ended: the glance to start (see [`Mixer::take_glance`]).
    glance: Option<Angle>,
    /// Bit `i`: axis `i` was on (a gesture or a gaze move playing on it) at
    /// the last frame mixed in full, and so at every frame since.
    on: u8,
    idle_on: bool,
    quiet_gain: [u32; 3],
    quiet_centre: [i32; 2],
    /// The limit modes from the next frame on.
    modes: [LimitMode; 3],
    idle_amp: Percent,
    /// The time of the last frame mixed in full.
    full: u32,
    /// The next time at which a layer or a gaze move ends, a return is due
    /// or starts, or the idle gain's glide ends, as last found (see
    /// `schedule`); events in between are settle times running out.
    ends: u32,
    /// µs each axis stays in gesture mode after it was last on, as of
    /// the last frame mixed in full (see [`Mixer::events`]).
    gesture_left: [u32; 3],
    /// Idle gain, Q16.
    idle_gain: Glide,
    params: BehaviourParams,
    gaze: Gaze,
    layers: [Option<Layer>; LAYERS],
    /// The rest layer.
    rest: Rest,
}

impl Mixer {
    /// A mixer at rest: idle at the configured amplitude, centre at the
    /// neutral pose, no gesture.
    #[must_use]
    pub const fn new(params: BehaviourParams) -> Self {
        let amp = params.config().idle.amplitude;
        Self {
            params,
            layers: [None; LAYERS],
            gaze: Gaze::new(),
            idle_gain: Glide::rest(q16(amp) as i32),
            idle_on: true,
            idle_amp: amp,
            gesture_left: [0; 3],
            on: 0,
            until: 0,
            full: 0,
            ends: 0,
            modes: [LimitMode::Idle; 3],
            quiet: true,
            quiet_unity: q16(amp) == ONE,
            resting: false,
            glance: None,
            quiet_gain: [q16(amp); 3],
            quiet_centre: [0; 2],
            rest: Rest::new(),
            now: 0,
            next: 0,
            period: params.frame_us(),
        }
    }

    /// Plays frames `period` apart after the last one mixed (see
    /// [`BehaviourParams::set_frame_period`]): the next frame comes
    /// `period` after it.
    pub(crate) fn set_frame_period(&mut self, period: Microseconds) {
        if period.0 == 0 {
            return;
        }
        self.params.set_frame_period(period);
        self.period = period.0;
        self.next = self.now.wrapping_add(period.0);
        // The next frame is mixed in full, and finds the events again (a
        // return is prepared one period before it starts).
        self.quiet = false;
        self.until = self.next;
        self.ends = self.next;
    }

    /// The parameters in use.
    #[must_use]
    pub const fn params(&self) -> &BehaviourParams {
        &self.params
    }

    /// Takes the live settings of `config` (see
    /// [`BehaviourParams::set_live`]); the rest pose from the next rest on.
    pub(crate) fn set_live(&mut self, live: &super::LiveConfig) {
        self.params.set_live(live);
        // The look's duck changes the quiet gains: mix the next frame in full.
        self.quiet = false;
        self.until = self.next;
    }

    /// Gives `axis` the servo's new angle limits (see
    /// [`Head::set_servo`](super::Head::set_servo)).
    pub(crate) fn set_angle_limits(&mut self, axis: crate::axis::Axis, limits: AngleRange) {
        self.params.set_angle_limits(axis, limits);
    }

    /// Applies `action`: the next frame is its first.
    ///
    /// `Stop` changes nothing here and answers [`Applied::Stop`]: stopping
    /// is the driver's fade (see [`Head`](super::Head)).
    ///
    /// # Errors
    /// A [`BehaviourError`] for bad parameters (nothing changes then).
    pub fn apply(&mut self, action: &Action) -> Result<Applied, BehaviourError> {
        self.apply_at(action, [Angle::ZERO; 3])
    }

    /// [`apply`](Self::apply) to a head whose last frame's offsets were
    /// `at` (`[pitch, roll, yaw]`, what the driver made of them): a rest's
    /// duration is fitted to the distance from there.
    ///
    /// # Errors
    /// A [`BehaviourError`] for bad parameters (nothing changes then).
    pub fn apply_at(&mut self, action: &Action, at: [Angle; 3]) -> Result<Applied, BehaviourError> {
        // Every action starts at the last frame mixed, where it is at its
        // start: the next frame, the first to play it, is already a step in
        // (begun at the next frame, that frame would only repeat where the
        // head is, and a command would show a frame later).
        let start = self.now;
        let next = self.next;
        let applied = match action {
            Action::Gesture(request) => {
                let plan = self.gesture(request)?;
                self.modes[request.kind.axis().index()] = LimitMode::Gesture;
                Applied::Gesture(plan)
            }
            Action::Look(request) => self.look(start, request)?,
            Action::Center { duration } => {
                let applied = self.gaze.center(&self.params, start, *duration)?;
                self.gazing();
                Applied::Center(applied)
            }
            Action::Idle(on) => {
                self.idle_on = *on;
                Applied::Idle(self.glide_idle())
            }
            Action::IdleAmp(amp) => {
                self.idle_amp = *amp;
                Applied::Idle(self.glide_idle())
            }
            Action::Stop => return Ok(Applied::Stop),
            Action::Rest => Applied::Rest(self.start_rest(start, at.map(Angle::millidegrees))),
            Action::Wake { toward } => match self.rest.wake(&self.params, start, *toward) {
                Some(duration) => Applied::Wake(duration),
                None => match toward {
                    // Awake already: the glance alone.
                    Some(yaw) => self.look(start, &rest::glance(&self.params, *yaw))?,
                    None => Applied::Wake(Millis(0)),
                },
            },
        };
        if matches!(action, Action::Gesture(_) | Action::Look(_)) {
            // A gesture or a look wakes a resting head: it plays over the
            // wake (a gesture on top of the blend, a look under it, arriving
            // as the idle comes back).
            self.rest.wake(&self.params, start, None);
        }
        self.resting = self.rest.active();
        self.quiet = false;
        // The next frame is mixed in full; the ends after it are known now.
        self.until = next;
        self.schedule(next);
        Ok(applied)
    }

    /// Starts a rest at time `start` of a head at `at` (offsets, m°): the
    /// pose's weight rises, and the gaze, hidden under it, goes back to the
    /// centre (a wake starts from there); returns the rest's duration.
    fn start_rest(&mut self, start: u32, at: [i32; 3]) -> Millis {
        let pose = self.params.rest_offsets();
        let duration = self.rest.rest(&self.params, start, pose, at);
        if !self.gaze.centred() {
            // Within the longest move: the built-in rest times are.
            let ms = duration.min(self.params.config().gaze.longest);
            let _ = self
                .gaze
                .center(&self.params, start, Some(Millis(ms.0.max(1))));
        }
        duration
    }

    /// The glance a wake with a direction ends in, once it is due: a look
    /// to apply before the next frame (what [`Head::sync`](super::Head::sync)
    /// does).
    pub fn take_glance(&mut self) -> Option<Action> {
        let yaw = self.glance.take()?;
        Some(Action::Look(rest::glance(&self.params, yaw)))
    }

    /// Where the head is in resting.
    #[must_use]
    pub const fn rest_state(&self) -> RestState {
        self.rest.state()
    }

    /// Whether the head rests at its pose with nothing moving, and should
    /// relax there (`rest.relax`): the driver may stop the pulses.
    #[must_use]
    pub const fn wants_relaxed(&self) -> bool {
        self.params.config().rest.relax
            && matches!(self.rest.state(), RestState::Resting)
            && self.rest.arrived()
    }

    /// A look starts at time `start` (µs).
    fn look(&mut self, start: u32, request: &LookRequest) -> Result<Applied, BehaviourError> {
        let applied = self.gaze.look(&self.params, start, request)?;
        self.gazing();
        Ok(Applied::Look(applied))
    }

    /// A gaze move starts: pitch and yaw in gesture mode.
    fn gazing(&mut self) {
        for axis in [crate::axis::Axis::Pitch, crate::axis::Axis::Yaw] {
            if let Some(mode) = self.modes.get_mut(axis.index()) {
                *mode = LimitMode::Gesture;
            }
        }
    }

    /// Glides the idle gain to its new target; returns the target.
    fn glide_idle(&mut self) -> Percent {
        let target = if self.idle_on {
            self.idle_amp
        } else {
            Percent::ZERO
        };
        let from = self.idle_gain.state(self.now);
        self.idle_gain = Glide::new(self.now, from, q16(target) as i32, self.params.idle_fade);
        target
    }

    /// The offsets of the frame at `at` for the driver, `[pitch, roll,
    /// yaw]`, over `idle` (the idle source's offsets of that frame).
    #[inline]
    pub fn frame(&mut self, at: Timestamp, idle: [Angle; 3]) -> [Angle; 3] {
        let now = at.wrapping();
        if !self.quiet {
            return self.mix(now, idle);
        }
        // Nothing moves but the idle: at its quiet gains, around the quiet
        // centre (within the limits: no overflow).
        self.now = now;
        self.next = now.wrapping_add(self.period);
        let [pitch, roll, yaw] = idle.map(Angle::millidegrees);
        let [centre_pitch, centre_yaw] = self.quiet_centre;
        let [pitch, roll, yaw] = if self.quiet_unity {
            [pitch, roll, yaw]
        } else {
            let [p, r, y] = self.quiet_gain;
            [mul(pitch, p), mul(roll, r), mul(yaw, y)]
        };
        [pitch + centre_pitch, roll, yaw + centre_yaw].map(Angle::from_millidegrees)
    }

    /// [`frame`](Self::frame) while anything but the idle moves.
    ///
    /// Written per axis rather than over arrays: on a Cortex-M0 the loops
    /// over `[_; 3]` cost more in spilled counters and pointers than their
    /// bodies (see [`Sums`]). The limit modes and whether the mixer is at
    /// rest only change at events (see [`events`](Self::events)); the frames
    /// between compute the values alone.
    #[inline(never)]
    fn mix(&mut self, now: u32, idle: [Angle; 3]) -> [Angle; 3] {
        let prev = self.now;
        self.now = now;
        self.next = now.wrapping_add(self.period);
        let sums = self.layers(now);

        let [centre_pitch, centre_yaw, envelope] = self.gaze.at(now);
        let gain = if self.idle_gain.moving() {
            self.idle_gain.at(now).clamp(0, ONE as i32) as u32
        } else {
            self.idle_gain.target() as u32
        };
        // The look's duck on pitch and yaw (1 without a look), with the gain.
        let look = look_keep(self.params.look_duck, envelope);
        let looked = both(gain, look);
        let [pitch, roll, yaw] = idle.map(Angle::millidegrees);
        // Within the limits: no overflow.
        let pitch = idle_part(pitch, looked, sums.duck[0]) + centre_pitch;
        let roll = idle_part(roll, gain, sums.duck[1]);
        let yaw = idle_part(yaw, looked, sums.duck[2]) + centre_yaw;
        let [pitch, roll, yaw] = if self.resting {
            self.rest.blend(now, [pitch, roll, yaw])
        } else {
            [pitch, roll, yaw]
        };
        let offsets = [pitch + sums.add[0], roll + sums.add[1], yaw + sums.add[2]];
        // `now < until` (times only increase).
        if self.until.wrapping_sub(now) as i32 <= 0 {
            self.events(
                now,
                prev,
                sums.active,
                [centre_pitch, centre_yaw],
                [gain, looked],
            );
        }
        offsets.map(Angle::from_millidegrees)
    }

    /// A frame mixed in full: the limit modes from the next frame on,
    /// whether the mixer comes to rest, and the next such frame.
    ///
    /// The modes: gesture while anything plays on the axis (or the return
    /// starts next frame) and `settle` after. An axis' state can only
    /// change at an *event*: a layer or a gaze move ends, the return is due
    /// or starts, the idle gain's glide ends, a settle time runs out, or an
    /// action is applied. Between two events each axis stays on or off, so
    /// its time left in gesture mode follows from the time passed: this
    /// gives the modes of every frame exactly as counting them down frame by
    /// frame would.
    ///
    /// `gains`: the idle's gain of this frame, on roll and on the look's
    /// axes.
    #[inline(never)]
    fn events(&mut self, now: u32, prev: u32, active: u8, centre: [i32; 2], gains: [u32; 2]) {
        if let Some(yaw) = self.rest.settle() {
            // Awake again: the glance, from the next frame on. It is applied
            // between frames, as an action is (its planning divides).
            self.glance = Some(yaw);
        }
        self.resting = self.rest.active();
        let moving = self.gaze.moving();
        let returning = self.gaze.returns_by(self.next);
        let on = active | u8::from(moving[0]) | (u8::from(moving[1]) << 2);
        let settle = self.params.settle;
        // Time since the last frame mixed, and since the last mixed in full.
        let since_prev = now.wrapping_sub(prev).max(1);
        let since_full = now.wrapping_sub(self.full).max(1);
        let was_on = self.on;
        let mut soonest = u32::MAX;
        let axis = Countdown {
            on,
            was_on,
            settle,
            since_prev,
            since_full,
        };
        let [pitch_left, roll_left, yaw_left] = &mut self.gesture_left;
        self.modes = [
            axis.mode(0, pitch_left, returning, &mut soonest),
            axis.mode(1, roll_left, false, &mut soonest),
            axis.mode(2, yaw_left, returning, &mut soonest),
        ];
        self.on = on;
        if LimitMode::same(self.modes, [LimitMode::Idle; 3])
            && self.layers.iter().all(Option::is_none)
            && !self.gaze.pending()
            && !self.idle_gain.moving()
            && !self.resting
        {
            let [gain, looked] = gains;
            self.quiet = true;
            self.quiet_centre = centre;
            self.quiet_gain = [looked, gain, looked];
            self.quiet_unity = gain == ONE && looked == ONE;
        }
        // The next end of a layer or a move: found again once the last one
        // found has passed, or after an action.
        if self.ends.wrapping_sub(now) as i32 <= 0 {
            self.schedule(now);
        }
        soonest = soonest.min(self.ends.wrapping_sub(now));
        // Every event lies ahead (at least the next frame); at rest, or
        // nothing due for 2³⁰ µs (about 18 minutes), the next frame mixed
        // in full is the first after an action or 2³⁰ µs on.
        self.full = now;
        self.until = now.wrapping_add(soonest.clamp(1, 1 << 30));
    }

    /// Finds the next time after `from` at which a layer or a gaze move
    /// ends, the return is due next frame or starts, or the idle gain's
    /// glide ends (`from + 2³⁰` if none). What ends at `from` or before is
    /// left to the frame mixed in full at `from` (an action's next frame,
    /// or the frame that found it due).
    #[inline]
    fn schedule(&mut self, from: u32) {
        let mut soonest = u32::MAX;
        for layer in self.layers.iter().flatten() {
            soonest = soonest.min(ahead(layer.end(), from));
        }
        soonest = soonest.min(self.gaze.next_event(from, self.period));
        if self.resting {
            soonest = soonest.min(self.rest.next_event(from));
        }
        if self.idle_gain.moving() {
            soonest = soonest.min(ahead(self.idle_gain.end(), from));
        }
        self.ends = from.wrapping_add(soonest.min(1 << 30));
    }

    /// The limit modes from the next frame on, `[pitch, roll, yaw]`: the
    /// driver should have them before the next frame is mixed.
    #[must_use]
    pub const fn modes(&self) -> [LimitMode; 3] {
        self.modes
    }

    /// Whether the idle is on (`idle on|off`).
    #[must_use]
    pub const fn idle_on(&self) -> bool {
        self.idle_on
    }

    /// The idle amplitude as last set (`idle amp`), whether the idle is on
    /// or off.
    #[must_use]
    pub const fn idle_amp(&self) -> Percent {
        self.idle_amp
    }
}
