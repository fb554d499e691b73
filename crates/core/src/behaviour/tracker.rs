//! The tracker: sightings in, gaze moves out (see [`super::Head::track`]).
//!
//! Between two frames the frame task hands over the sighting that came
//! since the last frame, if one did. [`Attention`](super::attention)
//! says where to look; the tracker turns that into moves of the gaze:
//!
//! - a new aim (someone to look at, a glance, back from it) is a look's
//!   move: the minimum-jerk glide in the look's time for the distance
//!   (300 ms + 8 ms per degree), from wherever the head is;
//! - a walker is followed by [`follow`](super::follow)'s glides, planned
//!   again at each sighting; a person standing still moves nothing;
//! - with nobody left, the gaze returns to the centre in the look's time.
//!
//! While a gaze move of the tracker's holds, the idle on pitch and yaw is
//! ducked as under a held look; gestures play over it. A console `look`
//! takes the gaze from the tracker until its return begins; a rest until
//! the head wakes. The show layer (DMX's mix slot, Bottango's curves)
//! blends over all of it, as over every look. Targets past the yaw limits
//! are followed to the limit and no further.

use crate::track::geometry::{bearing, pitch};
use crate::track::{Sighting, TrackSettings};
use crate::units::{Angle, Millis};

use super::attention::{Aim, Attention};
use super::follow::{Follow, GLIDE};
use super::mixer::Mixer;

/// How far down an aversion looks besides turning away, m° (people look
/// aside and a little down).
const AVERT_DOWN: i32 = 3_000;

/// What the tracker did between two frames, for the log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TrackEvent {
    /// Turned to a new aim at this yaw (axis angle, before the limits).
    Turned(Angle),
    /// Nobody left: the gaze returns to the centre.
    Released,
}

/// The tracker's state; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Tracker {
    attention: Attention,
    follow: Follow,
    /// The aim the gaze was last moved to.
    aim: Aim,
    /// Whom `follow` follows.
    attended: Option<usize>,
    /// When the last sighting came, µs.
    last: u64,
    /// The aim's yaw, for `watch`.
    at: Option<Angle>,
    /// The latest sighting, for `watch`.
    seen: Sighting,
    /// Whom attention attends to, as an index among `seen`'s people, if
    /// they are in it, for `watch`.
    who: Option<u8>,
}

impl Tracker {
    pub(crate) const fn new() -> Self {
        Self {
            attention: Attention::new(0x2545_f491),
            follow: Follow::at([0, 0]),
            aim: Aim::Nobody,
            attended: None,
            last: 0,
            at: None,
            seen: Sighting::NOBODY,
            who: None,
        }
    }

    /// The yaw the tracker aims at, if it holds the gaze.
    pub(crate) const fn aiming(&self) -> Option<Angle> {
        self.at
    }

    /// The latest sighting, and whom attention attends to among its
    /// people (see [`TrackView::who`](crate::track::TrackView::who)).
    pub(crate) const fn seen(&self) -> (&Sighting, Option<u8>) {
        (&self.seen, self.who)
    }

    /// Whom attention attends to among the latest sighting's people: the
    /// attended person's track, if that sighting updated it, is where one
    /// of them was.
    fn attended_in_sighting(&self) -> Option<u8> {
        let i = self.attention.attended()?;
        if !self.attention.fresh(i, self.last) {
            return None;
        }
        let at = self.attention.person(i)?;
        let k = self.seen.people.iter().flatten().position(|p| *p == at)?;
        Some(k as u8)
    }

    /// Between frames, at `now` µs: the sighting that came (if any) with
    /// `settings`, moves of `mixer`'s gaze as they follow.
    pub(crate) fn step(
        &mut self,
        mixer: &mut Mixer,
        now: u64,
        settings: &TrackSettings,
        sighting: Option<&Sighting>,
    ) -> Option<TrackEvent> {
        if let Some(s) = sighting {
            self.seen = *s;
        }
        if !settings.gazes() {
            self.who = None;
            return self.release(mixer);
        }
        let dt_ms = (now.saturating_sub(self.last) / 1000).min(u64::from(u32::MAX)) as u32;
        match sighting {
            Some(s) => {
                self.attention.sight(now, s, settings.prefer);
                self.last = now;
            }
            None if now >= self.attention.deadline() => self.attention.tick(now, settings.prefer),
            None => return None,
        }
        self.who = self.attended_in_sighting();
        let angles = |i: usize| {
            let person = self.attention.person(i)?;
            Some([pitch(&person, settings), bearing(&person, settings)])
        };
        // The attended person's filter runs on, through glances: coming
        // back, the head aims where it aimed (a person standing still is
        // met at the same angle, whatever the noise).
        let attended = self.attention.attended();
        if attended != self.attended {
            self.attended = attended;
            if let Some(z) = attended.and_then(angles) {
                self.follow = Follow::at(z);
            }
        }
        let mut moved = false;
        if let Some(i) = attended
            && self.attention.fresh(i, now)
            && let Some(z) = angles(i)
        {
            moved = self.follow.update(z, dt_ms);
        }
        if !mixer.gaze_free() {
            // A look or a rest holds the gaze: the aim is taken afresh
            // once it is free.
            self.aim = Aim::Nobody;
            self.at = None;
            return None;
        }
        let aim = self.attention.aim();
        let target = match aim {
            Aim::Nobody => return self.release(mixer),
            Aim::Person(i) if Some(i) == attended => self.follow.aims(),
            Aim::Person(i) => angles(i)?,
            Aim::Away(_, yaw) => {
                let [p, y] = self.follow.aims();
                [p + AVERT_DOWN, y + yaw]
            }
        };
        let to = target.map(Angle::from_millidegrees);
        if aim != self.aim || !mixer.gaze_tracked() {
            self.aim = aim;
            self.at = Some(to[1]);
            mixer.follow(to, None);
            return Some(TrackEvent::Turned(to[1]));
        }
        if moved && matches!(aim, Aim::Person(i) if Some(i) == attended) {
            self.at = Some(to[1]);
            mixer.follow(to, Some(Millis(GLIDE)));
        }
        None
    }

    /// Gives the gaze back to the centre, if the tracker holds it.
    fn release(&mut self, mixer: &mut Mixer) -> Option<TrackEvent> {
        self.aim = Aim::Nobody;
        self.at = None;
        if mixer.gaze_tracked() {
            mixer.unfollow();
            return Some(TrackEvent::Released);
        }
        None
    }
}
