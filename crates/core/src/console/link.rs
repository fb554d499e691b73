//! What the console task and the frame task share, besides the command
//! queue: the head's status (frame task → console), servo calibrations,
//! the servos' rate and the live behaviour settings to apply (console →
//! frame task), new
//! idle seeds (console → loop generator), the outcome of each port's
//! queued action (frame task → the port's console, which answers the line
//! with it), each port's telemetry rate (`watch`), and the trigger inputs'
//! settings and levels (console → input task → console).
//!
//! Each is a [`SharedCell`], a `Signal` (whose state is a `Cell` too) or a
//! [`Ring`] of `Cell`s: a critical section around a copy, no `RefCell`
//! borrow, so nothing here puts a panic path on the frame path.

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;

use crate::axis::Axis;
use crate::behaviour::{Applied, Asker, BehaviourError, LiveConfig};
use crate::driver::{DriverStats, FrameReport};
use crate::input::{InputSettings, InputStatus};
use crate::ring::Ring;
use crate::servo::{ServoCalibration, ServoRate};
use crate::shared::SharedCell;
use crate::track::TrackView;
use crate::units::{Angle, Microseconds, Timestamp};

/// What the driver is doing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HeadMode {
    /// No frame written yet.
    #[default]
    Starting,
    /// Playing (fading in or at full strength).
    Running,
    /// Gliding to the rest pose, or resting there (relaxed: no pulses).
    Resting,
    /// Waking from a rest: the idle fades back in.
    Waking,
    /// Fading out after `stop`.
    Stopping,
    /// Holding the neutral pose after `stop`.
    Stopped,
}

impl HeadMode {
    /// The word in `status`.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Starting => "starting",
            Self::Running => "running",
            Self::Resting => "resting",
            Self::Waking => "waking",
            Self::Stopping => "stopping",
            Self::Stopped => "stopped",
        }
    }
}

/// The head as the last frame left it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HeadStatus {
    /// The driver's frame count.
    pub frame: u64,
    /// The last frame's time since the first frame (whatever the frame
    /// rate was meanwhile).
    pub time: Timestamp,
    /// What the driver is doing.
    pub mode: HeadMode,
    /// Commanded angles `[pitch, roll, yaw]`.
    pub angles: [Angle; 3],
    /// Pulses written `[pitch, roll, yaw]`.
    pub pulses: [Microseconds; 3],
    /// Write errors per servo so far.
    pub faults: [u32; 3],
    /// Servos switched off.
    pub disabled: [bool; 3],
    /// The tracker, while the radar is on (`None`: off).
    pub track: Option<TrackView>,
    /// The idle motion as the mixer has it (`None`: not published).
    pub idle: Option<IdleView>,
}

/// The idle motion as the last frame left it, for `idle`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct IdleView {
    /// Whether it is on (`idle on|off`).
    pub on: bool,
    /// The amplitude last set (`idle amp`, an input's or DMX's), on or
    /// off.
    pub amp: crate::units::Percent,
}

impl HeadMode {
    /// The mode of a head whose driver is `stopped` or `stopping` (after a
    /// `stop`), and which is in `rest` otherwise.
    #[must_use]
    pub const fn of(stopped: bool, stopping: bool, rest: crate::behaviour::RestState) -> Self {
        use crate::behaviour::RestState;
        if stopped {
            Self::Stopped
        } else if stopping {
            Self::Stopping
        } else {
            match rest {
                RestState::Awake => Self::Running,
                RestState::Resting => Self::Resting,
                RestState::Waking => Self::Waking,
            }
        }
    }
}

impl HeadStatus {
    /// The status after the frame at `time` that wrote `report`.
    #[must_use]
    pub fn of(report: &FrameReport, stats: &DriverStats, mode: HeadMode, time: Timestamp) -> Self {
        Self {
            frame: report.frame,
            time,
            mode,
            angles: report.servos.map(|s| s.angle),
            pulses: report.servos.map(|s| s.pulse),
            faults: stats.faults,
            disabled: stats.disabled,
            track: None,
            idle: None,
        }
    }

    /// Time since the first frame, ms.
    #[must_use]
    pub const fn uptime_ms(&self) -> u64 {
        self.time.millis()
    }
}

/// Console ports a board may have: UART (0) and USB (1).
pub const PORTS: usize = 2;

/// Outcomes a port's mailbox holds: as many as the command queue holds
/// actions, so a port whose every queued action is taken in a row loses
/// none.
pub const OUTCOMES: usize = crate::behaviour::queue::CAPACITY;

/// What the frame task did with a port's queued action: its ticket and
/// what the mixer answered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Outcome {
    /// The ticket the console gave the action ([`Asker::ticket`]).
    pub ticket: u8,
    /// What it started, or why it was refused.
    pub result: Result<Applied, BehaviourError>,
}

/// The shared state; see the [module docs](self). Lives in a `static`.
pub struct ConsoleLink {
    status: SharedCell<HeadStatus>,
    servos: SharedCell<[Option<ServoCalibration>; 3]>,
    seeds: Signal<CriticalSectionRawMutex, [u32; 3]>,
    /// Each port's outcomes, in the order the frame task took its actions,
    /// and the signal that one arrived.
    outcomes: [Ring<Outcome, OUTCOMES>; PORTS],
    answered: [Signal<CriticalSectionRawMutex, ()>; PORTS],
    /// Telemetry lines a second per port (0: off).
    watch: SharedCell<[u8; PORTS]>,
    live: Signal<CriticalSectionRawMutex, LiveConfig>,
    /// The servos' rate to take (`servo rate`).
    rate: Signal<CriticalSectionRawMutex, ServoRate>,
    /// The inputs' settings in effect (one copy, which the input task
    /// reads at every wake), and whether they changed.
    inputs: SharedCell<InputSettings>,
    inputs_changed: Signal<CriticalSectionRawMutex, ()>,
    input_status: SharedCell<InputStatus>,
}

impl ConsoleLink {
    /// Nothing published, nothing pending.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            status: SharedCell::new(HeadStatus {
                frame: 0,
                time: Timestamp(0),
                mode: HeadMode::Starting,
                angles: [Angle::ZERO; 3],
                pulses: [Microseconds(0); 3],
                faults: [0; 3],
                disabled: [false; 3],
                track: None,
                idle: None,
            }),
            servos: SharedCell::new([None; 3]),
            seeds: Signal::new(),
            outcomes: [const { Ring::new() }; PORTS],
            answered: [const { Signal::new() }; PORTS],
            watch: SharedCell::new([0; PORTS]),
            live: Signal::new(),
            rate: Signal::new(),
            inputs: SharedCell::new(InputSettings::DEFAULT),
            inputs_changed: Signal::new(),
            input_status: SharedCell::new(InputStatus { high: 0, active: 0 }),
        }
    }

    /// The frame task: `asker`'s action was taken (or refused) with
    /// `result`. A port beyond [`PORTS`] is ignored; so is an outcome that
    /// finds the port's mailbox full (its console stopped reading: its
    /// reply was given up on already, [`super::unanswered`]).
    pub fn answer(&self, asker: Asker, result: Result<Applied, BehaviourError>) {
        let port = usize::from(asker.port);
        if let (Some(outcomes), Some(answered)) = (self.outcomes.get(port), self.answered.get(port))
        {
            let outcome = Outcome {
                ticket: asker.ticket,
                result,
            };
            if outcomes.push(outcome).is_ok() {
                answered.signal(());
            }
        }
    }

    /// The console of `port`: the oldest outcome of its actions not yet
    /// taken (`None` if none is there, or for a port beyond [`PORTS`]).
    pub fn take_outcome(&self, port: u8) -> Option<Outcome> {
        self.outcomes.get(usize::from(port))?.pop()
    }

    /// The console of `port`: waits until an outcome arrives (at once if
    /// one arrived since the last wait); for ever for a port beyond
    /// [`PORTS`].
    pub async fn answered(&self, port: u8) {
        match self.answered.get(usize::from(port)) {
            Some(signal) => signal.wait().await,
            None => core::future::pending().await,
        }
    }

    /// The console of `port`, when its host goes away: outcomes not taken
    /// are dropped (the lines they answer are forgotten).
    pub fn forget_outcomes(&self, port: u8) {
        if let Some(outcomes) = self.outcomes.get(usize::from(port)) {
            outcomes.clear();
        }
    }

    /// The console: `port` streams `hz` telemetry lines a second (0: none).
    pub fn set_watch(&self, port: u8, hz: u8) {
        self.watch.update(|rates| {
            if let Some(rate) = rates.get_mut(usize::from(port)) {
                *rate = hz;
            }
        });
    }

    /// The console: `port`'s telemetry rate in lines a second (0: none).
    pub fn watch(&self, port: u8) -> u8 {
        self.watch
            .get()
            .get(usize::from(port))
            .copied()
            .unwrap_or(0)
    }

    /// The frame task: the head after the last frame.
    pub fn publish(&self, status: HeadStatus) {
        self.status.set(status);
    }

    /// The console: the head after the last frame.
    pub fn status(&self) -> HeadStatus {
        self.status.get()
    }

    /// The console: `cal` for `axis`' servo from the next frame on. A
    /// calibration not yet applied is replaced (each is a whole
    /// calibration: the newest is the one asked for).
    pub fn set_servo(&self, axis: Axis, cal: ServoCalibration) {
        self.servos.update(|pending| {
            if let Some(slot) = pending.get_mut(axis.index()) {
                *slot = Some(cal);
            }
        });
    }

    /// The frame task: the calibrations to apply, `[pitch, roll, yaw]`.
    pub fn take_servos(&self) -> [Option<ServoCalibration>; 3] {
        self.servos.replace([None; 3])
    }

    /// Whether calibrations wait for the frame task.
    pub fn servos_pending(&self) -> bool {
        self.servos.get().iter().any(Option::is_some)
    }

    /// The console: generate the next loop set from `seeds`.
    pub fn reseed(&self, seeds: [u32; 3]) {
        self.seeds.signal(seeds);
    }

    /// The loop generator: new seeds, if asked for since the last call.
    pub fn take_seeds(&self) -> Option<[u32; 3]> {
        self.seeds.try_take()
    }

    /// The console: the rest pose, relax and the look's duck from the next
    /// frame on (the newest replaces one not yet taken).
    pub fn set_live(&self, live: LiveConfig) {
        self.live.signal(live);
    }

    /// The frame task: the live settings, if changed since the last call.
    pub fn take_live(&self) -> Option<LiveConfig> {
        self.live.try_take()
    }

    /// The console: the servos run at `rate` from a frame boundary on (the
    /// newest replaces one not yet taken).
    pub fn set_rate(&self, rate: ServoRate) {
        self.rate.signal(rate);
    }

    /// The frame task: the servos' rate, if the console set one since the
    /// last call.
    pub fn take_rate(&self) -> Option<ServoRate> {
        self.rate.try_take()
    }

    /// The boot, then the console: the inputs' roles and the rest timer in
    /// effect, for the input task.
    pub fn set_inputs(&self, inputs: InputSettings) {
        self.inputs.set(inputs);
        self.inputs_changed.signal(());
    }

    /// The input task: the inputs' settings in effect.
    pub fn input_settings(&self) -> InputSettings {
        self.inputs.get()
    }

    /// The input task: waits until the inputs' settings change.
    pub async fn inputs_changed(&self) {
        self.inputs_changed.wait().await;
    }

    /// The input task (or a host test): whether the inputs' settings changed
    /// since the last call.
    pub fn take_inputs_changed(&self) -> bool {
        self.inputs_changed.try_take().is_some()
    }

    /// The input task: the inputs' levels as they are now.
    pub fn publish_inputs(&self, status: InputStatus) {
        self.input_status.set(status);
    }

    /// The console: the inputs' levels.
    pub fn inputs(&self) -> InputStatus {
        self.input_status.get()
    }
}

impl Default for ConsoleLink {
    fn default() -> Self {
        Self::new()
    }
}

impl core::fmt::Debug for ConsoleLink {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ConsoleLink")
            .field("status", &self.status())
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::HeadStatus;

    #[test]
    fn uptime_is_the_last_frames_time() {
        let status = HeadStatus {
            frame: 50,
            time: crate::Timestamp(1_000_999),
            ..HeadStatus::default()
        };
        assert_eq!(status.uptime_ms(), 1000);
    }
}
