//! The console service: the [`Handler`] that carries out every command
//! ([`ConsoleService`], an example on it).
//!
//! Board-neutral: a board gives it the frame task's [`CommandQueue`], the
//! [`ConsoleLink`] shared with the frame task and the loop generator, its
//! [`SettingsStorage`] and its base driver configuration. Every line gets
//! one reply; motions are checked as the mixer would
//! ([`BehaviourParams::check`]) and queued, their reply deferred until the
//! frame task answers; settings are validated as a whole
//! ([`Settings::validate`]) before anything changes.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The console service”).

use crate::text::Arg::{Int, Str, Uint};
use crate::text::Text;

mod dmx;
mod inputs;
mod track;

use super::link::{ConsoleLink, HeadStatus};
use super::outcome::behaviour_code;
use super::reply::{ErrorCode, Reply};
use super::session::Handler;
use super::telemetry::{Angles, write_pose};
use crate::axis::Axis;
use crate::behaviour::{Asker, BehaviourParams, CommandQueue, ShowLink};
use crate::command::{Action, Command, ServoSetting};
use crate::driver::DriverConfig;
use crate::gestures::GestureKind;
use crate::servo::{Direction, ServoCalibration, ServoRate, bounds};
use crate::settings::{
    Settings, SettingsError, SettingsSource, SettingsStorage, StorageError, Validated,
};

/// The reply to `help`: the command words, one line (the gestures' from
/// the [gesture table](crate::gestures)).
pub const HELP: &str = const_format::concatcp!(
    "commands: help status stop",
    GestureKind::WORDS,
    " look center idle rest wake input seed servo save load defaults watch dmx radar track"
);

/// The firmware version `status` reports.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The console service; see the [module docs](self). On a RAM store:
///
/// ```
/// use idle_head_core::behaviour::CommandQueue;
/// use idle_head_core::console::{ConsoleLink, ConsoleService, Session};
/// use idle_head_core::driver::DriverConfig;
/// use idle_head_core::settings::{RamStorage, SETTINGS_BUFFER, Settings};
///
/// static QUEUE: CommandQueue = CommandQueue::new();
/// static LINK: ConsoleLink = ConsoleLink::new();
/// let mut service =
///     ConsoleService::with_defaults(&QUEUE, &LINK, RamStorage::<SETTINGS_BUFFER>::new());
/// let mut session = Session::<96, 160>::new();
/// let mut replies = Vec::new();
/// session.feed(b"servo yaw min 2600\nsave\n", &mut service, |r| replies.push(r.to_vec()));
/// assert!(replies[0].starts_with(b"err invalid "));
/// assert_eq!(replies[1], b"ok\r\n");
///
/// // A motion's reply waits for the frame task: it is queued, with a
/// // ticket, and answered with what the frame task did.
/// assert_eq!(session.push(b'n', &mut service), None);
/// for &b in b"od\n" {
///     assert_eq!(session.push(b, &mut service), None);
/// }
/// let ticket = session.waiting().unwrap();
/// assert_eq!(QUEUE.len(), 1);
/// // (the frame task takes it, and answers through the link:)
/// # let (action, asker) = QUEUE.take_asked().unwrap();
/// # let params = Settings::DEFAULT.validate(&DriverConfig::DEFAULT).unwrap().behaviour;
/// # LINK.answer(asker.unwrap(), params.check(&action));
/// let outcome = LINK.take_outcome(0).unwrap();
/// assert_eq!(outcome.ticket, ticket);
/// let reply = session.finish(|r| idle_head_core::console::outcome_reply(r, &outcome.result));
/// assert!(reply.unwrap().starts_with(b"ok nod amp_mdeg="));
/// ```
pub struct ConsoleService<'a, S, const N: usize = { crate::behaviour::queue::CAPACITY }> {
    queue: &'a CommandQueue<N>,
    link: &'a ConsoleLink,
    storage: S,
    base: DriverConfig,
    settings: Settings,
    behaviour: BehaviourParams,
    source: SettingsSource,
    /// xorshift32 state for `seed random`.
    entropy: u32,
    /// The last ticket given to a queued action.
    ticket: u8,
    /// The show layer's inputs (DMX settings and signal), on a board that
    /// has them.
    show: Option<&'a ShowLink>,
    /// The board's unique id (`seed board`).
    board: crate::seed::BoardId,
    /// What the board has (inputs, DMX, radar): none until
    /// [`with_parts`](Self::with_parts).
    parts: super::BoardParts,
}

impl<'a, S: SettingsStorage, const N: usize> ConsoleService<'a, S, N> {
    /// A service for a head that runs `settings` (from `source`) on the
    /// board's driver configuration `base`.
    ///
    /// # Errors
    /// The [`SettingsError`] if `settings` are not valid with `base`.
    pub fn new(
        queue: &'a CommandQueue<N>,
        link: &'a ConsoleLink,
        storage: S,
        base: DriverConfig,
        settings: Settings,
        source: SettingsSource,
    ) -> Result<Self, SettingsError> {
        let valid = settings.validate(&base)?;
        Ok(Self::checked(
            queue, link, storage, base, settings, source, &valid,
        ))
    }

    /// As [`new`](Self::new), with the settings checked already: `valid` is
    /// what `settings.validate(&base)` gave (a boot that checked the stored
    /// settings hands them over without checking them again).
    pub fn checked(
        queue: &'a CommandQueue<N>,
        link: &'a ConsoleLink,
        storage: S,
        base: DriverConfig,
        settings: Settings,
        source: SettingsSource,
        valid: &Validated,
    ) -> Self {
        Self {
            queue,
            link,
            storage,
            base,
            settings,
            behaviour: valid.behaviour,
            source,
            entropy: 0x9e37_79b9,
            ticket: 0,
            show: None,
            board: crate::seed::BoardId::NONE,
            parts: super::BoardParts::NONE,
        }
    }

    /// The service on a board that has `parts`: its inputs' numbers, and
    /// whether it has a DMX receiver and a radar (the commands for a part
    /// it lacks answer `err unavailable`).
    #[must_use]
    pub const fn with_parts(mut self, parts: super::BoardParts) -> Self {
        self.parts = parts;
        self
    }

    /// What the board has, as [`with_parts`](Self::with_parts) set it.
    #[must_use]
    pub const fn parts(&self) -> super::BoardParts {
        self.parts
    }

    /// A service on the built-in settings and driver configuration
    /// ([`Settings::DEFAULT`], [`DriverConfig::DEFAULT`], checked at compile
    /// time), saving to `storage`: a head as it leaves the factory.
    pub fn with_defaults(queue: &'a CommandQueue<N>, link: &'a ConsoleLink, storage: S) -> Self {
        Self::checked(
            queue,
            link,
            storage,
            DriverConfig::DEFAULT,
            Settings::DEFAULT,
            SettingsSource::Defaults,
            &Validated::DEFAULT,
        )
    }

    /// Mixes `bits` from the board's entropy source into `seed random`.
    pub fn add_entropy(&mut self, bits: u32) {
        self.entropy = (self.entropy ^ bits) | 1;
    }

    /// The settings in effect (as the console last set them).
    #[must_use]
    pub const fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Where they came from.
    #[must_use]
    pub const fn source(&self) -> SettingsSource {
        self.source
    }

    /// The board's store.
    pub fn storage_mut(&mut self) -> &mut S {
        &mut self.storage
    }

    fn act(&mut self, port: u8, action: Action, reply: &mut Reply<'_>) {
        if let Err(e) = self.behaviour.check(&action) {
            text(reply.err(behaviour_code(&e))).with(&e);
            return;
        }
        self.ticket = self.ticket.wrapping_add(1);
        let asker = Asker {
            port,
            ticket: self.ticket,
        };
        match self.queue.try_submit_from(action, asker) {
            Ok(()) => {
                // The console's idle amplitude is a setting, kept with
                // `save` (an input's or DMX's is not).
                if let Action::IdleAmp(amp) = action
                    && amp != self.settings.behaviour.idle.amplitude
                {
                    self.settings.behaviour.idle.amplitude = amp;
                    self.source = SettingsSource::Changed;
                }
                reply.defer(asker.ticket);
            }
            Err(full) => {
                text(reply.err(ErrorCode::Busy)).with(&full);
            }
        }
    }

    fn watch(&mut self, port: u8, hz: Option<u8>, reply: &mut Reply<'_>) {
        self.link.set_watch(port, hz.unwrap_or(0));
        let text = text(reply.ok()).str("watch=");
        match hz {
            Some(hz) => text.u64(hz.into()),
            None => text.str("off"),
        };
    }

    fn status(&self, reply: &mut Reply<'_>) {
        let s: HeadStatus = self.link.status();
        let [fp, fr, fy] = s.faults;
        let off = s.disabled.iter().filter(|&&d| d).count();
        text(reply.ok()).str("mode=").str(s.mode.as_str());
        write_pose(text(reply), &s, Angles::Joined);
        text(reply).fill(
            " faults={},{},{} off={} uptime_ms={} fw={}{} settings={}",
            &[
                Uint(fp.into()),
                Uint(fr.into()),
                Uint(fy.into()),
                Uint(off as u64),
                Uint(s.uptime_ms()),
                Str(VERSION),
                Str(self.dmx_status()),
                Str(self.source.as_str()),
            ],
        );
        self.status_inputs(text(reply));
        self.status_track(text(reply));
        // The servos' rate, as set (the frame task takes it at the next
        // frame boundary).
        text(reply)
            .str(" rate=")
            .u64(self.settings.rate.hz().into());
    }

    fn show_servo(&self, axis: Axis, reply: &mut Reply<'_>) {
        let c = self.settings.servo(axis);
        text(reply.ok()).fill(
            "{} neutral={} per-degree={} direction={} min={} max={} limits={},{}",
            &[
                Str(axis.name()),
                Uint(c.neutral.0.into()),
                Uint(c.per_degree.0.into()),
                Str(match c.direction {
                    Direction::Normal => "normal",
                    Direction::Reversed => "reversed",
                }),
                Uint(c.min_pulse.0.into()),
                Uint(c.max_pulse.0.into()),
                Int(c.limits.min.millidegrees().into()),
                Int(c.limits.max.millidegrees().into()),
            ],
        );
    }

    fn set_servo(&mut self, axis: Axis, setting: ServoSetting, reply: &mut Reply<'_>) {
        let mut next = self.settings;
        let Some(cal) = next.servos.get_mut(axis.index()) else {
            return;
        };
        change(cal, setting);
        let cal = *cal;
        if let ServoSetting::Limits(limits) = setting {
            let at = self.link.status().angles[axis.index()];
            if !limits.contains(at) {
                text(reply.err(ErrorCode::Limit)).fill(
                    "the {} servo stands at {} mdeg, outside {}..{}: move it in first",
                    &[
                        Str(axis.name()),
                        Int(at.millidegrees().into()),
                        Int(limits.min.millidegrees().into()),
                        Int(limits.max.millidegrees().into()),
                    ],
                );
                return;
            }
        }
        match next.validate(&self.base) {
            Ok(valid) if self.inputs_refused(&next, &valid.behaviour, reply) => {}
            Ok(valid) => {
                self.link.set_servo(axis, cal);
                self.settings = next;
                self.behaviour = valid.behaviour;
                self.source = SettingsSource::Changed;
                if let Some(pulse) = cal.unusual() {
                    text(reply.ok()).fill(
                        "warning: {} pulses may reach {} us, outside the {}..{} us most hobby servos accept: check the servo's travel",
                        &[
                            Str(axis.name()),
                            Uint(pulse.0.into()),
                            Uint(bounds::TYPICAL_MIN.0.into()),
                            Uint(bounds::TYPICAL_MAX.0.into()),
                        ],
                    );
                }
            }
            Err(SettingsError::Driver(e)) => {
                text(reply.err(ErrorCode::Invalid)).with(&e);
            }
            Err(SettingsError::Behaviour(e)) => {
                text(reply.err(ErrorCode::Limit))
                    .str("the head would go past the new limits: ")
                    .with(&e);
            }
        }
    }

    /// `servo rate`: the rate, and the period it runs at (whole µs).
    fn show_rate(&self, reply: &mut Reply<'_>) {
        let rate = self.settings.rate;
        text(reply.ok()).fill(
            "servo rate={} period_us={}",
            &[Uint(rate.hz().into()), Uint(rate.period().0.into())],
        );
    }

    /// `servo rate <hz>`: checked as the settings at that rate (those in
    /// effect are valid: only what the rate changes), then sent to the
    /// frame task, which takes it at a frame boundary.
    fn set_rate(&mut self, rate: ServoRate, reply: &mut Reply<'_>) {
        let mut next = self.settings;
        next.rate = rate;
        match next.validate_rate(&self.base) {
            Ok(valid) if self.inputs_refused(&next, &valid.behaviour, reply) => {}
            Ok(valid) => {
                self.link.set_rate(rate);
                self.settings = next;
                self.behaviour = valid.behaviour;
                self.source = SettingsSource::Changed;
                self.show_rate(reply);
            }
            Err(SettingsError::Driver(e)) => {
                text(reply.err(ErrorCode::Invalid)).with(&e);
            }
            Err(SettingsError::Behaviour(e)) => {
                text(reply.err(ErrorCode::Limit))
                    .str("the behaviour does not hold at that rate: ")
                    .with(&e);
            }
        }
    }

    /// Puts `settings` in effect: idle amplitude through the queue (so a
    /// full queue changes nothing), servos and seeds through the link.
    fn adopt(
        &mut self,
        settings: &Settings,
        source: SettingsSource,
        reply: &mut Reply<'_>,
    ) -> bool {
        let valid = match settings.validate(&self.base) {
            Ok(valid) => valid,
            Err(e) => {
                text(reply.err(ErrorCode::Invalid)).with(&e);
                return false;
            }
        };
        let amp = settings.behaviour.idle.amplitude;
        if amp != self.settings.behaviour.idle.amplitude
            && let Err(full) = self.queue.try_submit(Action::IdleAmp(amp))
        {
            text(reply.err(ErrorCode::Busy)).with(&full);
            return false;
        }
        for (axis, (new, old)) in Axis::ALL
            .iter()
            .zip(settings.servos.iter().zip(&self.settings.servos))
        {
            if new != old {
                self.link.set_servo(*axis, *new);
            }
        }
        if settings.idle_seeds(self.board) != self.settings.idle_seeds(self.board) {
            self.link.reseed(settings.idle_seeds(self.board));
        }
        if settings.rate != self.settings.rate {
            self.link.set_rate(settings.rate);
        }
        if let Some(show) = self.show {
            show.dmx.set(settings.dmx);
            show.track.set(settings.track);
        }
        self.settings = *settings;
        self.behaviour = valid.behaviour;
        self.source = source;
        self.adopt_inputs();
        true
    }

    fn load(&mut self, reply: &mut Reply<'_>) {
        match self.storage.load() {
            Ok(settings) => {
                self.adopt(&settings, SettingsSource::Flash, reply);
            }
            Err(e) => storage_error(e, "load", reply),
        }
    }

    fn save(&mut self, reply: &mut Reply<'_>) {
        match self.storage.save(&self.settings) {
            Ok(()) => self.source = SettingsSource::Flash,
            Err(e) => storage_error(e, "save", reply),
        }
    }
}

impl<S: SettingsStorage, const N: usize> ConsoleService<'_, S, N> {
    /// Carries out `command` from console port `port` (which waits for
    /// the outcome of a queued action, and has its own telemetry rate).
    pub fn command_on(&mut self, port: u8, command: Command, reply: &mut Reply<'_>) {
        match command {
            Command::Help => {
                text(reply.ok()).str(HELP);
            }
            Command::Status => self.status(reply),
            Command::Act(action) => self.act(port, action, reply),
            Command::Watch(hz) => self.watch(port, hz, reply),
            Command::Seed(choice) => self.seed(choice, reply),
            Command::ServoRate(None) => self.show_rate(reply),
            Command::ServoRate(Some(rate)) => self.set_rate(rate, reply),
            Command::Servo {
                axis,
                setting: None,
            } => self.show_servo(axis, reply),
            Command::Servo {
                axis,
                setting: Some(setting),
            } => self.set_servo(axis, setting, reply),
            Command::Save => self.save(reply),
            Command::Load => self.load(reply),
            Command::Defaults => {
                self.adopt(&Settings::DEFAULT, SettingsSource::Defaults, reply);
            }
            Command::Dmx(setting) => self.dmx(setting, reply),
            Command::Input { input, role: None } => self.show_input(input, reply),
            Command::Input {
                input,
                role: Some(role),
            } => self.set_input(input, role, reply),
            Command::Rest(None) => self.show_rest(reply),
            Command::Rest(Some(setting)) => self.set_rest(setting, reply),
            Command::LookDuck(None) => self.show_look_duck(reply),
            Command::LookDuck(Some(duck)) => self.set_look_duck(duck),
            Command::IdleQuery => self.show_idle(reply),
            Command::SeedQuery => self.show_seed(text(reply.ok())),
            Command::Radar(on) => self.radar(on, reply),
            Command::Track(setting) => self.track(setting, reply),
        }
    }
}

/// As a handler of its own, the service is port 0's.
impl<S: SettingsStorage, const N: usize> Handler for ConsoleService<'_, S, N> {
    fn command(&mut self, command: Command, reply: &mut Reply<'_>) {
        self.command_on(0, command, reply);
    }
}

impl<S, const N: usize> core::fmt::Debug for ConsoleService<'_, S, N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ConsoleService")
            .field("settings", &self.settings)
            .field("source", &self.source)
            .finish_non_exhaustive()
    }
}

/// `cal` with `setting` applied.
fn change(cal: &mut ServoCalibration, setting: ServoSetting) {
    match setting {
        ServoSetting::Neutral(us) => cal.neutral = us,
        ServoSetting::PerDegree(ns) => cal.per_degree = ns,
        ServoSetting::Direction(d) => cal.direction = d,
        ServoSetting::MinPulse(us) => cal.min_pulse = us,
        ServoSetting::MaxPulse(us) => cal.max_pulse = us,
        ServoSetting::Limits(range) => cal.limits = range,
    }
}

fn storage_error(e: StorageError, what: &str, reply: &mut Reply<'_>) {
    let code = match e {
        StorageError::Absent => ErrorCode::Unavailable,
        _ => ErrorCode::Storage,
    };
    text(reply.err(code)).str(what).str(": ").with(&e);
}

/// A reply as the [`Text`] its words are written into.
fn text<'r>(reply: &'r mut Reply<'_>) -> &'r mut dyn Text {
    reply
}
