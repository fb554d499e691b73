//! Trackers: sensors that say where people are, and what the head shares
//! of them between the receiver, the frame task and the console.
//!
//! - [`Sighting`]: what any tracker reports, up to [`PEOPLE`] people as
//!   positions in the sensor's own frame ([`Person`], millimetres).
//! - [`SightingSource`]: the seam a tracker goes behind: raw input in (a
//!   UART's bytes, a register block read over I2C), whole sightings out,
//!   with its [`Counters`]. The HLK-LD2450 radar is one
//!   ([`ld2450::Decoder`]); a camera person sensor would be another.
//! - [`TrackLink`]: the latest sighting and the counters, from the
//!   receiver to the frame task (the gaze, [`crate::behaviour::attention`])
//!   and to the input task (presence, [`crate::input`]); the settings
//!   ([`TrackSettings`]) from the console.
//! - [`geometry`]: a person's bearing and the pitch to their eyes, in
//!   integers.
//!
//! # The sensor's frame
//!
//! A sensor reports `x` across and `y` away from it, in mm: `y > 0` in
//! front, `x > 0` to the sensor's right as seen from behind it (looking
//! where it looks). A person straight ahead is at `x = 0`. Which way the
//! head turns for that is the head's sign convention (`docs/user/radar.md`):
//! `+yaw` turns the head to its own left, so a person at `x > 0` is at a
//! negative bearing.

pub mod geometry;
pub mod ld2450;
mod link;

pub use link::{Received, TrackLink};

use crate::units::{Angle, Millimetres};

/// The tracker as the last frame left it, for `watch`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackView {
    /// The latest sighting the frame task took.
    pub seen: Sighting,
    /// Whom the head attends to, if they are in `seen`: the index among
    /// its people, counted in slot order over the slots that hold someone
    /// (as `watch` lists them).
    pub who: Option<u8>,
    /// The yaw the head aims at (an axis angle), if it follows someone.
    pub at: Option<Angle>,
}

impl TrackView {
    /// People in the latest sighting.
    #[must_use]
    pub fn targets(&self) -> u8 {
        self.seen.count()
    }
}

/// People a sighting holds at most (the LD2450 tracks three).
pub const PEOPLE: usize = 3;

/// One person's position in the sensor's frame (see the [module
/// docs](self#the-sensors-frame)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Person {
    /// Across: to the sensor's right as seen from behind it.
    pub x: Millimetres,
    /// Away from the sensor: in front is positive.
    pub y: Millimetres,
}

/// What a tracker saw at one moment: up to [`PEOPLE`] people, each in a
/// slot the tracker keeps for them while it can (an empty slot is
/// `None`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sighting {
    /// The people, by the tracker's slot.
    pub people: [Option<Person>; PEOPLE],
}

impl Sighting {
    /// Nobody.
    pub const NOBODY: Self = Self {
        people: [None; PEOPLE],
    };

    /// How many people it holds.
    #[must_use]
    pub fn count(&self) -> u8 {
        self.people.iter().filter(|p| p.is_some()).count() as u8
    }
}

/// A tracker's frames since it started, by what became of them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Counters {
    /// Whole frames, each a sighting.
    pub good: u32,
    /// Frames that began but arrived damaged: a wrong end, or a receive
    /// error (bytes lost) inside them. Ignored.
    pub bad: u32,
    /// Good frames the frame task never took: a newer one replaced each
    /// before the next frame (the frame task stalled). Counted by the link.
    pub dropped: u32,
    /// Bytes skipped outside frames while looking for the next start (a
    /// wrong baud rate shows here).
    pub skipped: u32,
}

/// A tracker behind the head's seam: raw input in, sightings out.
///
/// A board's receiver feeds it what the sensor sent, in order and in any
/// pieces, and reports receive errors; it never blocks, allocates or
/// panics on any input. The LD2450 radar's [`ld2450::Decoder`] is one; a
/// camera person sensor read over I2C would be another (its register
/// block as the input), and nothing after the seam would change.
pub trait SightingSource {
    /// Takes `input`, calling `seen` with each whole sighting in it.
    fn feed(&mut self, input: &[u8], seen: &mut dyn FnMut(Sighting));

    /// The receiver lost or damaged input here (an overrun, a framing
    /// error): the sighting under way is dropped.
    fn error(&mut self);

    /// What became of the frames so far.
    fn counters(&self) -> Counters;
}

/// Whom the head attends to first (`track prefer`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Prefer {
    /// The nearest person (the default: who walks up to the head).
    #[default]
    Nearest,
    /// The newest arrival (a head that greets whoever comes in).
    Newest,
}

impl Prefer {
    /// The word in the console.
    #[must_use]
    pub const fn word(self) -> &'static str {
        match self {
            Self::Nearest => "nearest",
            Self::Newest => "newest",
        }
    }
}

/// The tracker's settings (`radar …`, `track …`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackSettings {
    /// Whether the radar is used at all (`radar on|off`; off by default:
    /// a board with nothing wired behaves as without one).
    pub radar: bool,
    /// Whether the head also looks at people (`track on|off`), or the
    /// radar is presence only.
    pub gaze: bool,
    /// The height of a visitor's eyes above the head's pivot
    /// (`track height`), in [`HEIGHT`].
    pub height: Millimetres,
    /// The radar's bearing when the head is at yaw 0 (`track mount`), in
    /// [`MOUNT`]: the yaw the head turns to for someone straight in front
    /// of the radar.
    pub mount: Angle,
    /// Whom the head attends to.
    pub prefer: Prefer,
}

/// The heights `track height` takes, mm.
pub const HEIGHT: (i32, i32) = (-3000, 3000);
/// The bearings `track mount` takes, m°.
pub const MOUNT: (i32, i32) = (-180_000, 180_000);

impl TrackSettings {
    /// Radar off; once on, the head looks at people, at eye height 300 mm
    /// above its pivot (a head at about 1.3 m, adults' eyes at 1.6 m),
    /// the radar straight ahead, the nearest person first.
    pub const DEFAULT: Self = Self {
        radar: false,
        gaze: true,
        height: Millimetres(300),
        mount: Angle::ZERO,
        prefer: Prefer::Nearest,
    };

    /// Whether the head turns to people: the radar on, and `track on`.
    #[must_use]
    pub const fn gazes(&self) -> bool {
        self.radar && self.gaze
    }

    /// The height, held within [`HEIGHT`] (a stored value past it is
    /// used at the bound).
    #[must_use]
    pub const fn height_mm(&self) -> i32 {
        let h = self.height.0;
        if h < HEIGHT.0 {
            HEIGHT.0
        } else if h > HEIGHT.1 {
            HEIGHT.1
        } else {
            h
        }
    }

    /// The mount bearing, held within [`MOUNT`].
    #[must_use]
    pub const fn mount_mdeg(&self) -> i32 {
        let m = self.mount.millidegrees();
        if m < MOUNT.0 {
            MOUNT.0
        } else if m > MOUNT.1 {
            MOUNT.1
        } else {
            m
        }
    }
}

impl Default for TrackSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}
