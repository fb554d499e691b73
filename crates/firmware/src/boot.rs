//! The boot sequence every board runs before its first frame, and the
//! firmware's singletons.
//!
//! A board reads its settings store ([`crate::storage::open`], or
//! [`Loaded::defaults`] for a board without one) and calls [`boot`], which
//!
//! 1. logs the servo configuration the head starts with;
//! 2. generates loop set 0 from the settings' seeds into the first of the
//!    two loop set buffers and logs what it took;
//! 3. starts the never-repeating stream from it, hands the second buffer to
//!    the generator, and makes the console service;
//!
//! and returns what the board's tasks need: the frame task's first set and
//! parameters, the generator's stream, the console's service. The board then
//! spawns the frame task above the generator and the console ports (see
//! `idle-head-rp` for the RP boards, `boards/qemu` for QEMU).

use embassy_time::Instant;
use idle_head_core::Axis;
use idle_head_core::behaviour::{BehaviourParams, CommandQueue};
use idle_head_core::console::{ConsoleLink, ConsoleService};
use idle_head_core::driver::{DriverConfig, DriverParams};
use idle_head_core::idle::{IdleMode, LoopStream};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadConfig};
use idle_head_core::settings::{Settings, SettingsSource, SettingsStorage, Validated};
use static_cell::ConstStaticCell;

use crate::config::{DEFAULT_TIMING, IDLE_MODE, Set, SetRef};
use crate::exchange::Exchange;

/// Actions from the console ports (and the inputs) to the frame task, which
/// it drains between frames.
pub static COMMANDS: CommandQueue = CommandQueue::new();

/// Status, servo calibrations and seeds between the console and the frame
/// task (and the loop generator).
pub static LINK: ConsoleLink = ConsoleLink::new();

/// The channels the loop set buffers go round through.
pub static EXCHANGE: Exchange = Exchange::new();

/// The two loop set buffers, 2 · 5.4 KB: one plays while the generator
/// fills the other. All zero (the neutral pose) until generated.
static SETS: ConstStaticCell<[Set; 2]> = ConstStaticCell::new([Set::new(), Set::new()]);

/// The built-in settings, checked with the built-in driver configuration at
/// compile time.
pub const DEFAULT_SETTINGS: Validated = match Settings::DEFAULT.validate(&DriverConfig::DEFAULT) {
    Ok(v) => v,
    Err(_) => panic!("the built-in settings fail validation"),
};

/// The settings a board boots with, and the storage the console saves to.
pub struct Loaded<S> {
    /// The console's storage.
    pub storage: S,
    /// The settings in effect.
    pub settings: Settings,
    /// Where they came from.
    pub source: SettingsSource,
    /// Their parameters for the driver and the behaviour.
    pub valid: Validated,
}

impl<S> Loaded<S> {
    /// The built-in settings, with `storage` for the console's `save`.
    pub const fn defaults(storage: S) -> Self {
        Self {
            storage,
            settings: Settings::DEFAULT,
            source: SettingsSource::Defaults,
            valid: DEFAULT_SETTINGS,
        }
    }

    /// The idle motion's configuration with these settings' seeds.
    #[must_use]
    pub const fn head(&self) -> HeadConfig {
        let mut head = DEFAULT_HEAD;
        head.pitch.seed = self.settings.seeds[0];
        head.roll.seed = self.settings.seeds[1];
        head.yaw.seed = self.settings.seeds[2];
        head
    }
}

/// How a board times the boot precompute, and in what unit it logs it.
pub trait Stopwatch {
    /// Runs `work`, returning how long it took in this stopwatch's unit.
    fn time(&mut self, work: &mut dyn FnMut()) -> u64;
    /// The unit, for the log (`"us"`, `"instructions"`).
    fn unit(&self) -> &'static str;
}

/// Times with embassy-time's clock, in microseconds.
pub struct Clock;

impl Stopwatch for Clock {
    fn time(&mut self, work: &mut dyn FnMut()) -> u64 {
        let start = Instant::now();
        work();
        start.elapsed().as_micros()
    }

    fn unit(&self) -> &'static str {
        "us"
    }
}

/// What the boot sequence hands the board's tasks.
pub struct Booted<S: 'static> {
    /// Loop set 0, generated: the frame task plays it first.
    pub first: SetRef,
    /// The never-repeating stream for the generator task (`None` for the
    /// fixed loop).
    pub stream: Option<LoopStream<DEFAULT_N>>,
    /// The driver's parameters of the settings in effect.
    pub driver: DriverParams,
    /// The behaviour's parameters of the settings in effect.
    pub behaviour: BehaviourParams,
    /// The console's service, on the board's storage.
    pub service: Option<ConsoleService<'static, S>>,
    /// Loop set 0's checksum (the host computes the same).
    pub checksum: u32,
    /// Whether loop set 0 was generated (else it holds the neutral pose).
    pub generated: bool,
    /// What generating loop set 0 took, in the stopwatch's unit.
    pub precompute: u64,
}

/// Why [`boot`] could not run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum BootError {
    /// The loop set buffers were taken already: `boot` runs once.
    AlreadyBooted,
}

/// The boot sequence (see the [module docs](self)) on the board's driver
/// configuration `base`, with the settings `loaded`; `entropy` is mixed into
/// the console's `seed random`.
///
/// # Errors
/// [`BootError::AlreadyBooted`] if called a second time.
pub fn boot<S: SettingsStorage>(
    base: &DriverConfig,
    loaded: Loaded<S>,
    stopwatch: &mut dyn Stopwatch,
    entropy: u32,
) -> Result<Booted<S>, BootError> {
    log_servos(base, &loaded);
    let [first, spare] = SETS.try_take().ok_or(BootError::AlreadyBooted)?;
    let head = loaded.head();
    let mut generated = Err(None);
    let precompute = stopwatch.time(&mut || generated = first.generate(&head).map_err(Some));
    let generated = match generated {
        Ok(info) => {
            for (axis, info) in Axis::ALL.iter().zip(info.iter()) {
                defmt::info!(
                    "{=str}: split at sample {=u16} of {=u16} zero crossings, {=u16} up-steps",
                    axis.name(),
                    info.split,
                    info.crossings,
                    info.up_steps
                );
            }
            true
        }
        // The loop is left at the neutral pose: the servos hold still.
        Err(Some(e)) => {
            defmt::error!(
                "trajectory generation failed: {=str} {=str}",
                e.axis.name(),
                e.error.message()
            );
            false
        }
        Err(None) => false,
    };
    let checksum = first.checksum();
    defmt::info!(
        "precompute: {=u64} {=str}; checksum {=u32:#010x}",
        precompute,
        stopwatch.unit(),
        checksum
    );
    let stream = match IDLE_MODE {
        IdleMode::NeverRepeating => {
            // The stream starts from the boot set, whose pace it measures
            // (a fixed loop has no stream and skips that).
            let mut stream = LoopStream::new(head, &DEFAULT_TIMING);
            stream.adopt(first);
            defmt::info!(
                "idle: never repeating, a new loop set every {=u32} frames, joined over {=u32}",
                DEFAULT_TIMING.period(),
                DEFAULT_TIMING.join_frames
            );
            EXCHANGE.give(spare);
            Some(stream)
        }
        IdleMode::FixedLoop => {
            defmt::info!("idle: the fixed loop, replayed every loop");
            None
        }
    };
    let Loaded {
        storage,
        settings,
        source,
        valid,
    } = loaded;
    let service = match ConsoleService::new(&COMMANDS, &LINK, storage, *base, settings, source) {
        Ok(mut service) => {
            service.add_entropy(checksum ^ entropy);
            Some(service)
        }
        Err(e) => {
            defmt::error!("console: no service: {}", e);
            None
        }
    };
    Ok(Booted {
        first,
        stream,
        driver: valid.driver,
        behaviour: valid.behaviour,
        service,
        checksum,
        generated,
        precompute,
    })
}

/// Logs each servo's calibration as the head starts with it.
fn log_servos<S>(base: &DriverConfig, loaded: &Loaded<S>) {
    let _ = base;
    for (axis, servo) in Axis::ALL.iter().zip(loaded.settings.servos.iter()) {
        defmt::info!(
            "{=str}: neutral {=u32} us, {=u32} ns/deg, pulses [{=u32}, {=u32}] us, limits [{=i32}, {=i32}] mdeg",
            axis.name(),
            servo.neutral.0,
            servo.per_degree.0,
            servo.min_pulse.0,
            servo.max_pulse.0,
            servo.limits.min.millidegrees(),
            servo.limits.max.millidegrees()
        );
    }
}
