//! The frame engine: idle source, mixer and frame driver, one call per frame.
//!
//! The embassy frame task and the host trace both call [`Head::frame`]
//! (after [`Head::drain`] for queued commands): the same code, the same
//! numbers. The driver stays the caller's (the board hooks get it between
//! frames); the head borrows it for each call.
//!
//! Between frames ([`Head::sync`], also part of [`Head::apply`] and
//! [`Head::drain`]) the head switches each axis' speed and acceleration
//! limits between the idle mode (the driver's configured limits, which the
//! parameters were built with) and the gesture mode, as the mixer asks
//! ([`LimitMode`]): the gesture limits as soon as a motion is applied (or a
//! planned return is due next frame), the idle limits back once the axis has
//! settled. Like any change of the driver's limits, a switch is made between
//! two frames, not during one, and only once the driver's axis can take the
//! new limits ([`FrameDriver::set_motion_limits_when_safe`]): an axis still moving
//! faster than the idle limits allow, or too fast to stop before an angle
//! limit at the idle acceleration (the driver's fade after a stop moves the
//! target too, which the mixer does not see), keeps its gesture limits until
//! it can.

use embedded_hal::pwm::SetDutyCycle;

use crate::axis::Axis;
use crate::command::Action;
use crate::driver::{ConfigError, FrameDriver, FrameReport, RateError};
use crate::servo::ServoCalibration;
use crate::units::{Angle, Microseconds, Timestamp};

use super::config::LiveConfig;
use super::error::BehaviourError;
use super::idle::IdleSource;
use super::mixer::{Applied, Mixer};
use super::params::{BehaviourParams, LimitMode};
use super::queue::{Asker, CommandQueue, PER_FRAME};
use super::rest::RestState;
use super::show::{Show, ShowEvents, Source};
use super::tracker::{TrackEvent, Tracker};
use crate::bottango::Sample;
use crate::dmx::{Latest, Signal};
use crate::track::{Sighting, TrackSettings};

/// What one frame did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HeadFrame {
    /// The mixer's offsets `[pitch, roll, yaw]`: what the driver got.
    pub offsets: [Angle; 3],
    /// What the driver wrote.
    pub report: FrameReport,
}

/// The frame engine; see the [module docs](self).
#[derive(Clone, Debug)]
pub struct Head<I> {
    idle: I,
    mixer: Mixer,
    /// The show layer over the mixer's offsets.
    show: Show,
    /// The limit mode the driver has, per axis.
    modes: [LimitMode; 3],
    /// The tracker (a radar's sightings to gaze moves).
    tracker: Tracker,
}

impl<I> Head<I> {
    /// A head playing `idle` with the behaviour `params`.
    pub const fn new(idle: I, params: BehaviourParams) -> Self {
        Self {
            idle,
            mixer: Mixer::new(params),
            show: Show::new(&params),
            modes: [LimitMode::Idle; 3],
            tracker: Tracker::new(),
        }
    }
}

impl<I: IdleSource> Head<I> {
    /// The mixer.
    pub fn mixer(&self) -> &Mixer {
        &self.mixer
    }

    /// The limit modes the driver has, `[pitch, roll, yaw]` (the mixer's
    /// [`modes`](Mixer::modes) once each switch was made).
    pub const fn limit_modes(&self) -> [LimitMode; 3] {
        self.modes
    }

    /// The idle source.
    pub fn idle_mut(&mut self) -> &mut I {
        &mut self.idle
    }

    /// Applies `action` from the next frame on. `Stop` fades the driver out;
    /// a gesture, a look, `idle on`, `idle amp` or `wake` after a stop fades
    /// it in again. An axis that starts moving gets its gesture limits at
    /// once. A gesture, a look or `wake` brings back the pulses of a head
    /// relaxed at rest, from where it stands.
    ///
    /// # Errors
    /// A [`BehaviourError`] for bad parameters; nothing changes then.
    pub fn apply<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        action: &Action,
    ) -> Result<Applied, BehaviourError> {
        let pose = driver.params().config().neutral_pose;
        let angles = driver.angles();
        let at = core::array::from_fn(|i| angles[i].saturating_sub(pose[i]));
        let applied = self.mixer.apply_at(action, at)?;
        if let Action::IdleAmp(amp) = action {
            self.show.own_amp(*amp);
        }
        match action {
            Action::Stop => driver.request_stop(),
            Action::Gesture(_)
            | Action::Look(_)
            | Action::Idle(true)
            | Action::IdleAmp(_)
            | Action::Wake { .. } => {
                driver.resume();
            }
            Action::Center { .. } | Action::Idle(false) | Action::Rest => {}
        }
        self.sync(driver);
        Ok(applied)
    }

    /// Between frames: the rest pose, relax and the look's duck of
    /// `live`, as the console changed them (the pose clamped to the
    /// servos' limits). A new pose takes effect at the next rest (or `rest`
    /// again); relax at once.
    pub fn set_live<P: SetDutyCycle>(&mut self, driver: &mut FrameDriver<P>, live: &LiveConfig) {
        self.mixer.set_live(live);
        self.sync(driver);
    }

    /// Where the head is in resting.
    pub const fn rest_state(&self) -> RestState {
        self.mixer.rest_state()
    }

    /// Between frames: a new calibration for `axis`' servo
    /// ([`FrameDriver::set_servo`]: the servo moves to it through its speed
    /// limits), and its angle limits for the behaviour too: looks are
    /// clamped to the new limits and gestures checked against them, as the
    /// console checked the commands it queued.
    ///
    /// # Errors
    /// The [`ConfigError`] the driver refused it with; nothing changes then.
    pub fn set_servo<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        axis: Axis,
        cal: ServoCalibration,
    ) -> Result<(), ConfigError> {
        driver.set_servo(axis, cal)?;
        self.mixer.set_angle_limits(axis, cal.limits);
        Ok(())
    }

    /// Between frames: the frames come `period` apart from the next one on
    /// (`servo rate`: the second step, after the frame that
    /// [`FrameDriver::set_pwm_period`] came before; see the driver's
    /// `frame/rate.rs`). The driver's per-frame limits, speed and fade, the
    /// mixer's clock and its limit modes' rates, and the idle source's step
    /// take the new period; everything else is timed in µs and goes on as
    /// it was: the same motion, sampled at the new rate.
    ///
    /// # Errors
    /// The [`RateError`] the driver refused it with; nothing changes then.
    pub fn set_frame_period<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        period: Microseconds,
    ) -> Result<(), RateError> {
        driver.set_frame_period(period)?;
        self.mixer.set_frame_period(period);
        self.idle.set_frame_period(period);
        Ok(())
    }

    /// Between frames: gives the driver the limits of the modes the mixer
    /// asks for from the next frame on (see the [module docs](self)), stops
    /// or brings back the pulses as the rest asks (relaxed at the rest
    /// pose), and starts the glance a wake ended in.
    pub fn sync<P: SetDutyCycle>(&mut self, driver: &mut FrameDriver<P>) {
        let mut wanted = self.mixer.modes();
        let show = self.show.engaged();
        if show != 0 {
            for (i, mode) in wanted.iter_mut().enumerate() {
                if show & (1 << i) != 0 {
                    *mode = LimitMode::Gesture;
                }
            }
        }
        if !LimitMode::same(wanted, self.modes) {
            self.switch(driver, wanted);
        }
        let relaxed = self.mixer.wants_relaxed();
        if relaxed != driver.is_relaxed() {
            driver.set_relaxed(relaxed);
        }
        if let Some(glance) = self.mixer.take_glance() {
            // A wake ended with a direction: the glance, as a look. (It is
            // clamped to the limits and never refused: a failure changes
            // nothing.)
            let _ = self.apply(driver, &glance);
        }
    }

    /// Between frames: [`sync`](Self::sync), then up to [`PER_FRAME`]
    /// queued actions, telling `done` each action and its outcome; returns
    /// how many.
    pub fn drain<P: SetDutyCycle, const N: usize>(
        &mut self,
        driver: &mut FrameDriver<P>,
        queue: &CommandQueue<N>,
        mut done: impl FnMut(&Action, &Result<Applied, BehaviourError>),
    ) -> usize {
        self.drain_asked(driver, queue, |action, _, outcome| done(action, outcome))
    }

    /// [`drain`](Self::drain), telling `done` also who asked for each
    /// action (the console port waiting for its outcome, if any).
    pub fn drain_asked<P: SetDutyCycle, const N: usize>(
        &mut self,
        driver: &mut FrameDriver<P>,
        queue: &CommandQueue<N>,
        mut done: impl FnMut(&Action, Option<Asker>, &Result<Applied, BehaviourError>),
    ) -> usize {
        self.sync(driver);
        let mut count = 0;
        while count < PER_FRAME {
            let Some((action, asker)) = queue.take_asked() else {
                break;
            };
            let outcome = self.apply(driver, &action);
            done(&action, asker, &outcome);
            count += 1;
        }
        count
    }

    /// Plays the frame at `at`: idle offsets, mixed, through `driver`
    /// (which starts with neutral pulses on its first frame).
    pub fn frame<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        at: Timestamp,
    ) -> HeadFrame {
        let idle = self.idle.offsets(at);
        let mut offsets = self.mixer.frame(at, idle);
        self.show.blend(at.wrapping(), &mut offsets);
        HeadFrame {
            offsets,
            report: driver.write_frame(offsets),
        }
    }

    /// Between frames, before the frame at `at`: the show layer's inputs (see
    /// [`show`](super::show)): the DMX link's state and latest cue (`None`
    /// on a board without DMX) and Bottango's curves as sampled for this
    /// frame (`None` without a session). A gesture the DMX trigger fires
    /// and the idle amplitude it sets are applied here (neither wakes a
    /// head that `stop` stopped); returns what happened, for the log.
    pub fn show<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        at: Timestamp,
        dmx: Option<(bool, Latest)>,
        curves: Option<Sample>,
    ) -> ShowEvents {
        let now = at.wrapping();
        self.show
            .bottango(now, curves, self.mixer.params().neutral_pose());
        let mut events = ShowEvents::default();
        if let Some(dmx) = dmx {
            let amp = self.mixer.idle_amp();
            let asked = self.show.dmx(now, dmx, amp, self.mixer.params());
            events.signal = asked.signal;
            if let Some(action) = asked.fired {
                events.fired = Some((action, self.mixer.apply(&action)));
            }
            // An idle amplitude always applies (a glide to it).
            if let Some(amp) = asked.idle {
                let _ = self.mixer.apply(&Action::IdleAmp(amp));
            }
        }
        self.sync(driver);
        events
    }

    /// Between frames, before the frame at `at`: the tracker's `sighting`
    /// that came since the last frame (if any), with `settings` (see
    /// [`tracker`](super::tracker)); what it did, for the log. Cheap when
    /// nothing came and nothing is due.
    pub fn track<P: SetDutyCycle>(
        &mut self,
        driver: &mut FrameDriver<P>,
        at: Timestamp,
        settings: &TrackSettings,
        sighting: Option<&Sighting>,
    ) -> Option<TrackEvent> {
        let event = self
            .tracker
            .step(&mut self.mixer, at.micros(), settings, sighting);
        if event.is_some() || sighting.is_some() {
            self.sync(driver);
        }
        event
    }

    /// The yaw the tracker aims the head at (an axis angle, before the
    /// limits), if it holds the gaze.
    pub const fn tracking(&self) -> Option<Angle> {
        self.tracker.aiming()
    }

    /// The tracker for `watch`: the latest sighting, whom the head attends
    /// to in it, and the yaw the head aims at.
    pub const fn track_view(&self) -> crate::track::TrackView {
        let (seen, who) = self.tracker.seen();
        crate::track::TrackView {
            seen: *seen,
            who,
            at: self.tracker.aiming(),
        }
    }

    /// The idle motion as the mixer has it, for `idle`: on or off, and the
    /// amplitude last set (by the console, an input or DMX).
    pub const fn idle_view(&self) -> crate::console::IdleView {
        crate::console::IdleView {
            on: self.mixer.idle_on(),
            amp: self.mixer.idle_amp(),
        }
    }

    /// What drives the show layer.
    pub const fn show_source(&self) -> Source {
        self.show.source()
    }

    /// The DMX signal as the show layer last judged it.
    pub const fn dmx_signal(&self) -> Signal {
        self.show.signal()
    }

    /// Gives the driver the limits of `modes` where they changed. (They were
    /// validated with the parameters. Should the axis not be able to take
    /// them yet, or the driver refuse them, the axis keeps its limits and the
    /// switch is tried again next frame.)
    #[inline(never)]
    fn switch<P: SetDutyCycle>(&mut self, driver: &mut FrameDriver<P>, modes: [LimitMode; 3]) {
        let params = self.mixer.params();
        for ((axis, &wanted), mode) in Axis::ALL.iter().zip(&modes).zip(&mut self.modes) {
            let limits = params.limits(*axis, wanted);
            if wanted != *mode
                && driver.set_rates_when_safe(
                    *axis,
                    limits,
                    params.rates(*axis, wanted),
                    params.frame_us(),
                ) == Ok(true)
            {
                *mode = wanted;
            }
        }
    }
}
