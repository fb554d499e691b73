//! The show layer: a pose from a lighting console ([DMX](crate::dmx)) or
//! from Bottango's curves ([`crate::bottango`]), blended over everything
//! else the mixer made (idle, gestures, gaze).
//!
//! The blend weight follows the source (DMX's mix slot, Bottango's
//! session) and moves without a jump; when the source goes away the head
//! hands back to the mixer smoothly. The inputs arrive through the
//! [`ShowLink`], which the receivers and the console ports write and the
//! frame task reads between frames.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The show layer”).

use crate::bottango::{Curves, Sample};
use crate::command::{Action, GestureKind, GestureRequest, Percent};
use crate::dmx::{Cue, DmxLink, Latest, Signal, Trigger};
use crate::track::TrackLink;
use crate::units::{Angle, Millis};

use super::error::BehaviourError;
use super::fixed::{ONE, mul};
use super::glide::{Glide, State};
use super::mixer::Applied;
use super::params::BehaviourParams;

/// How long the DMX signal may stay away before the head plays on its own.
pub const LOSS: Millis = Millis(1000);
/// How long the hand-back to the head's own motion takes.
pub const HANDBACK: Millis = Millis(500);

/// What drives the layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Source {
    /// Nothing: the head's own motion.
    None,
    /// A lighting console.
    Dmx,
    /// Bottango's curves.
    Bottango,
}

/// The show layer's inputs, shared with the DMX receiver and the console
/// ports (Bottango sessions); lives in a `static`.
#[derive(Debug, Default)]
pub struct ShowLink {
    /// The DMX receiver's cues and the DMX settings.
    pub dmx: DmxLink,
    /// The Bottango session's curves.
    pub curves: Curves,
    /// The tracker's sightings and settings (a radar's): the gaze's input,
    /// not the show layer's, carried here so that every receiver's data
    /// reaches the frame task and the console through one link.
    pub track: TrackLink,
}

impl ShowLink {
    /// Nothing received, DMX on at address 1, no Bottango session.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            dmx: DmxLink::new(),
            curves: Curves::new(),
            track: TrackLink::new(),
        }
    }
}

/// What the show's inputs did between two frames, for the log.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ShowEvents {
    /// The DMX signal changed to this.
    pub signal: Option<Signal>,
    /// The gesture trigger entered a band: the action it asked for, and
    /// what the mixer answered.
    pub fired: Option<(Action, Result<Applied, BehaviourError>)>,
}

/// What [`Show::dmx`] asks the mixer for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Asked {
    /// The DMX signal changed to this.
    pub(crate) signal: Option<Signal>,
    /// A gesture (or `center`) the trigger fired.
    pub(crate) fired: Option<Action>,
    /// The idle amplitude to set.
    pub(crate) idle: Option<Percent>,
}

/// The show layer's state; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Show {
    /// Bit `i`: the layer drives axis `i` (0: the layer is off).
    axes: u8,
    /// The pose, m° from the neutral pose, `[pitch, roll, yaw]`.
    pose: [i32; 3],
    /// `w`, Q16, while it does not glide.
    weight: u32,
    /// The hand-back: `w` gliding to 0.
    handback: Option<Glide>,
    source: Source,
    /// The last DMX cue's number, and the time it came at (µs).
    seq: u32,
    cue_at: u32,
    signal: Signal,
    /// The gesture trigger's band (`None` before the first cue).
    band: Option<Trigger>,
    /// The idle amplitude DMX set last, while DMX holds it, and the head's
    /// own to give back.
    dmx_amp: Option<Percent>,
    own_amp: Percent,
    /// [`LOSS`] and [`HANDBACK`] in µs.
    loss: u32,
    handback_us: u32,
}

impl Show {
    /// Off, no signal heard yet.
    pub(crate) const fn new(params: &BehaviourParams) -> Self {
        Self {
            axes: 0,
            pose: [0; 3],
            weight: 0,
            handback: None,
            source: Source::None,
            seq: 0,
            cue_at: 0,
            signal: Signal::Lost,
            band: None,
            dmx_amp: None,
            own_amp: params.config().idle.amplitude,
            loss: BehaviourParams::micros(LOSS),
            handback_us: BehaviourParams::micros(HANDBACK),
        }
    }

    /// What drives the layer.
    pub(crate) const fn source(&self) -> Source {
        self.source
    }

    /// Bit `i`: the layer moves axis `i` (also while it hands back).
    pub(crate) const fn engaged(&self) -> u8 {
        self.axes
    }

    /// The offsets at time `now`: the mixer's, `offsets`, blended with the
    /// show's pose in place.
    #[inline]
    pub(crate) fn blend(&mut self, now: u32, offsets: &mut [Angle; 3]) {
        if self.axes != 0 {
            self.blend_on(now, offsets);
        }
    }

    /// [`blend`](Self::blend) while the layer is on.
    #[inline(never)]
    fn blend_on(&mut self, now: u32, offsets: &mut [Angle; 3]) {
        let axes = self.axes;
        let w = match &mut self.handback {
            Some(glide) => {
                let w = glide.at(now).clamp(0, ONE as i32) as u32;
                if !glide.moving() {
                    // Handed back: the layer is off from the next frame.
                    self.handback = None;
                    self.weight = 0;
                    self.axes = 0;
                    self.source = Source::None;
                }
                w
            }
            None => self.weight,
        };
        for (i, (slot, &pose)) in offsets.iter_mut().zip(&self.pose).enumerate() {
            if axes & (1 << i) != 0 {
                let m = slot.millidegrees();
                // Both within ±360°: the difference fits.
                *slot = Angle::from_millidegrees(m + mul(pose - m, w));
            }
        }
    }

    /// Between frames, before the frame at `now`: hands back from the current
    /// `w` (no change if already handing back or off).
    fn release(&mut self, now: u32) {
        if self.axes == 0 || self.handback.is_some() {
            return;
        }
        if self.weight == 0 {
            self.axes = 0;
            self.source = Source::None;
            return;
        }
        self.handback = Some(Glide::new(
            now,
            State::rest(self.weight as i32),
            0,
            self.handback_us,
        ));
    }

    /// Between frames, before the frame at `now`: Bottango's curves as sampled for
    /// it. While they play they drive the axes they have.
    pub(crate) fn bottango(&mut self, now: u32, sample: Option<Sample>, neutral: [Angle; 3]) {
        match sample {
            Some(s) if s.playing && s.axes != 0 => {
                for (i, (pose, (&angle, &zero))) in self
                    .pose
                    .iter_mut()
                    .zip(s.angles.iter().zip(&neutral))
                    .enumerate()
                {
                    if s.axes & (1 << i) != 0 {
                        *pose = offset(angle, zero);
                    }
                }
                self.source = Source::Bottango;
                self.axes = s.axes;
                self.weight = ONE;
                self.handback = None;
            }
            _ if self.source == Source::Bottango => self.release(now),
            _ => {}
        }
    }

    /// Between frames, before the frame at `now`: the DMX link's state (`on`, and
    /// its latest cue), the mixer's idle amplitude `amp`; `room` is each
    /// axis' offsets around the neutral pose.
    pub(crate) fn dmx(
        &mut self,
        now: u32,
        (on, latest): (bool, Latest),
        amp: Percent,
        params: &BehaviourParams,
    ) -> Asked {
        let mut events = Asked::default();
        if !on {
            if self.signal != Signal::Off {
                self.signal = Signal::Off;
                events.signal = Some(Signal::Off);
                self.lose(now, &mut events);
            }
            return events;
        }
        if self.signal == Signal::Off {
            self.signal = Signal::Lost;
            events.signal = Some(Signal::Lost);
        }
        if latest.seq != self.seq {
            self.seq = latest.seq;
            self.cue_at = now;
            if self.signal != Signal::Ok {
                self.signal = Signal::Ok;
                events.signal = Some(Signal::Ok);
            }
            self.cue(&latest.cue, amp, params, &mut events);
        } else if self.signal == Signal::Ok && now.wrapping_sub(self.cue_at) >= self.loss {
            self.signal = Signal::Lost;
            events.signal = Some(Signal::Lost);
            self.lose(now, &mut events);
        }
        events
    }

    /// A new DMX cue.
    fn cue(&mut self, cue: &Cue, amp: Percent, params: &BehaviourParams, events: &mut Asked) {
        if self.source != Source::Bottango {
            for (i, (pose, &value)) in self.pose.iter_mut().zip(&cue.pose).enumerate() {
                let room = params.room[i];
                let (lo, hi) = (room.min.millidegrees(), room.max.millidegrees());
                // lo + (hi − lo)·value/65 535: value·65 536/65 535 is
                // value + value/2¹⁵ to within one count (0 → 0, 65 535 →
                // 65 536, exact at both ends), a Q16 fraction of the span.
                let fraction = u32::from(value) + (u32::from(value) >> 15);
                *pose = lo + mul(hi - lo, fraction);
            }
            self.weight = (u32::from(cue.mix) * ONE + 127) / 255;
            self.source = Source::Dmx;
            self.handback = None;
            self.axes = if self.weight == 0 { 0 } else { 0b111 };
        }
        let band = Trigger::of(cue.trigger);
        if let Some(previous) = self.band
            && previous != band
        {
            events.fired = match band {
                Trigger::None => None,
                Trigger::Gesture(kind) => Some(gesture(kind)),
                Trigger::Center => Some(Action::Center { duration: None }),
            };
        }
        self.band = Some(band);
        let wanted = Percent::new(cue.intensity_percent()).unwrap_or(Percent::FULL);
        if self.dmx_amp != Some(wanted) {
            if self.dmx_amp.is_none() {
                self.own_amp = amp;
            }
            self.dmx_amp = Some(wanted);
            events.idle = Some(wanted);
        }
    }

    /// The DMX signal went away (lost or switched off): hand back, and give
    /// the idle amplitude back.
    fn lose(&mut self, now: u32, events: &mut Asked) {
        if self.source == Source::Dmx {
            self.release(now);
        }
        if self.dmx_amp.take().is_some() {
            events.idle = Some(self.own_amp);
        }
    }

    /// The console set the idle amplitude: while DMX holds it, this is the
    /// amplitude to give back.
    pub(crate) fn own_amp(&mut self, amp: Percent) {
        if self.dmx_amp.is_some() {
            self.own_amp = amp;
        }
    }

    /// The DMX signal as last judged.
    pub(crate) const fn signal(&self) -> Signal {
        self.signal
    }
}

/// `angle` (m°) as an offset from `zero`, within the limiter's range.
fn offset(angle: i32, zero: Angle) -> i32 {
    angle.clamp(-360_000, 360_000) - zero.millidegrees()
}

/// A gesture at its defaults.
const fn gesture(kind: GestureKind) -> Action {
    Action::Gesture(GestureRequest::new(kind))
}
