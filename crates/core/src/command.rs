//! What the head can be asked to do: the command vocabulary shared by the
//! serial console ([`crate::console`]), the behaviour mixer and the host
//! trace scripts, in the project's units (millidegrees, milliseconds,
//! microseconds, nanoseconds per degree).
//!
//! An optional field left `None` takes the configured default (the
//! behaviour settings decide amplitudes, durations and intensities).

use crate::axis::Axis;
use crate::servo::{Direction, NanosPerDegree};
use crate::units::{Angle, AngleRange, Microseconds, Millis};

pub use crate::gestures::GestureKind;
pub use crate::units::Percent;

/// A gesture as asked for; `None` fields take the configured defaults.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GestureRequest {
    /// Which gesture.
    pub kind: GestureKind,
    /// Peak amplitude. Most gestures take a positive amplitude; a posture's
    /// (a tilt's) sign chooses the side (see [`Shape`](crate::gestures::Shape)).
    pub amplitude: Option<Angle>,
    /// Total duration.
    pub duration: Option<Millis>,
    /// Number of cycles (up to the gesture's
    /// [`max_cycles`](crate::gestures::Gesture::max_cycles)).
    pub cycles: Option<u8>,
    /// How brisk: faster and fuller at 100 %, slow and soft at 0 %.
    pub intensity: Option<Percent>,
}

impl GestureRequest {
    /// A gesture with every parameter at its default.
    #[must_use]
    pub const fn new(kind: GestureKind) -> Self {
        Self {
            kind,
            amplitude: None,
            duration: None,
            cycles: None,
            intensity: None,
        }
    }
}

/// What the head does after a look has arrived.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Hold {
    /// Return to the centre after this long.
    Return(Millis),
    /// Stay until told otherwise (`center` or another `look`).
    Stay,
}

/// A gaze target as asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LookRequest {
    /// Target pitch of the head's centre.
    pub pitch: Angle,
    /// Target yaw of the head's centre.
    pub yaw: Angle,
    /// Duration of the move (`None`: from the distance).
    pub duration: Option<Millis>,
    /// What to do once there (`None`: the configured default).
    pub hold: Option<Hold>,
}

/// A request for the frame task: it changes what the head does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Action {
    /// Play a gesture over the idle motion.
    Gesture(GestureRequest),
    /// Move the head's centre to a target.
    Look(LookRequest),
    /// Move the head's centre back to the neutral pose.
    Center {
        /// Duration of the move (`None`: from the distance).
        duration: Option<Millis>,
    },
    /// Switch the idle motion on (`true`) or off (`false`), smoothly.
    Idle(bool),
    /// Scale the idle motion, smoothly.
    IdleAmp(Percent),
    /// Fade all motion out to the neutral pose and hold it.
    Stop,
    /// Glide to the rest pose (the idle fades out) and stay there; relax
    /// there if the settings say so (see [`crate::behaviour::rest`]).
    Rest,
    /// Wake from a rest: the idle fades back in. With a direction, glance
    /// there once awake (or at once, if awake already).
    Wake {
        /// The glance's yaw (an axis angle, as a look's), if any.
        toward: Option<Angle>,
    },
}

/// Where the idle motion's random stream starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SeedChoice {
    /// This seed.
    Value(u32),
    /// A seed drawn from the board's entropy source.
    Random,
    /// The seed derived from the board's unique id (the default).
    Board,
    /// The paper's Table 2 seeds.
    Paper,
}

/// One field of a servo's calibration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoSetting {
    /// Pulse at the neutral angle.
    Neutral(Microseconds),
    /// Pulse change per degree.
    PerDegree(NanosPerDegree),
    /// Sense of rotation.
    Direction(Direction),
    /// Shortest pulse.
    MinPulse(Microseconds),
    /// Longest pulse.
    MaxPulse(Microseconds),
    /// Mechanical angle limits.
    Limits(AngleRange),
}

impl ServoSetting {
    /// The field's name in the protocol.
    #[must_use]
    pub const fn field(&self) -> &'static str {
        match self {
            Self::Neutral(_) => "neutral",
            Self::PerDegree(_) => "per-degree",
            Self::Direction(_) => "direction",
            Self::MinPulse(_) => "min",
            Self::MaxPulse(_) => "max",
            Self::Limits(_) => "limits",
        }
    }
}

/// What a trigger input is (see [`crate::input`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InputRole {
    /// Not used (the default): its level means nothing.
    #[default]
    Off,
    /// A push button to ground, active low with the internal pull-up: a
    /// press runs `action`, any motion line the console accepts.
    Button(Action),
    /// A presence sensor (a PIR module), active high: someone there keeps
    /// the head awake and wakes it; with a direction, the head glances
    /// there (a yaw, as a look's).
    Presence {
        /// Where the sensor looks, if given.
        toward: Option<Angle>,
    },
}

/// When the head rests with nobody there (see [`crate::input`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RestAfter {
    /// Never: presence inputs only wake the head and make it glance.
    Never,
    /// After this many seconds (`1..=`[`MAX_REST_AFTER`]) without presence.
    Seconds(u32),
}

/// The longest `rest after`: a day, in seconds.
pub const MAX_REST_AFTER: u32 = 86_400;

/// A change of the rest settings (`rest after|pose|relax`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RestSetting {
    /// When the head rests with nobody there.
    After(RestAfter),
    /// The rest pose, `[pitch, roll, yaw]`.
    Pose([Angle; 3]),
    /// Whether the pulses stop once there.
    Relax(bool),
}

/// One line of the console protocol, parsed ([`crate::console::parse`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// List the commands.
    Help,
    /// Report mode, angles, pulses, faults, uptime, version, settings source.
    Status,
    /// Change what the head does.
    Act(Action),
    /// Restart the idle motion's random stream.
    Seed(SeedChoice),
    /// Show (`None`) or set the servos' PWM rate, and with it the frame
    /// rate (`servo rate [hz]`).
    ServoRate(Option<crate::servo::ServoRate>),
    /// Show (`None`) or change one field of a servo's calibration.
    Servo {
        /// The servo's axis.
        axis: Axis,
        /// The change, if any.
        setting: Option<ServoSetting>,
    },
    /// Store the settings in flash.
    Save,
    /// Load the settings stored in flash.
    Load,
    /// Go back to the built-in settings (not stored until `save`).
    Defaults,
    /// Stream telemetry lines on this port, this many a second
    /// (`1..=50`), or stop them (`None`).
    Watch(Option<u8>),
    /// Show the DMX receiver's state and counters (`None`), or change a
    /// DMX setting.
    Dmx(Option<DmxSetting>),
    /// Show (`None`) or change a trigger input's role.
    Input {
        /// The input's number, as the console names it: one of the
        /// board's [`InputIds`](crate::input::InputIds) (GP2 to GP5 on
        /// the Pico), which the service checks, not the parser.
        input: u8,
        /// The new role, if any.
        role: Option<InputRole>,
    },
    /// Show the rest settings (`None`: `rest after`, `rest pose` or
    /// `rest relax` alone), or change one.
    Rest(Option<RestSetting>),
    /// Show (`None`) or set how much a held look ducks the idle on its
    /// axes.
    LookDuck(Option<Percent>),
    /// Show the idle motion: on or off, and its amplitude (`idle` alone).
    IdleQuery,
    /// Show the seed in use.
    SeedQuery,
    /// Show the radar's state and counters (`None`), or switch it on or off.
    Radar(Option<bool>),
    /// Show (`None`) or change a tracking setting.
    Track(Option<TrackSetting>),
}

/// A tracking setting (`track …`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TrackSetting {
    /// The head looks at people (`true`), or the radar is presence only.
    Gaze(bool),
    /// The height of a visitor's eyes above the head's pivot.
    Height(crate::units::Millimetres),
    /// The radar's bearing when the head is at yaw 0.
    Mount(Angle),
    /// Whom the head attends to first.
    Prefer(crate::track::Prefer),
}

/// A DMX setting (`dmx on|off`, `dmx address <n>`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DmxSetting {
    /// DMX drives the head (`true`) or not.
    On(bool),
    /// The head's start address.
    Address(crate::dmx::DmxAddress),
}
