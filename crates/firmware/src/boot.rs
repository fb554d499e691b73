//! The boot sequence every board runs before its first frame, and the
//! firmware's singletons.
//!
//! A board reads its settings store ([`crate::storage::open`], or
//! [`Loaded::defaults`] for a board without one) and calls [`boot`], which
//! logs the servo configuration the head starts with, takes the two loop set
//! buffers and makes the console service; it returns what the board's tasks
//! need. The board then spawns the loop generator, the frame task above it
//! and the console ports (see `idle-head-rp` for the RP boards,
//! `boards/qemu` for QEMU).
//!
//! The generator's first job is loop set 0, from the settings' seeds
//! ([`crate::tasks::generate`]): the frame task waits for it before its
//! first frame. Generating it there rather than here keeps the deepest
//! stack of the boot (the generation) on the generator's own, shallow
//! frame, instead of on top of everything the boot sequence holds.

use core::cell::RefCell;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_time::Instant;
use idle_head_core::Axis;
use idle_head_core::behaviour::{BehaviourParams, CommandQueue, ShowLink};
use idle_head_core::console::{BoardParts, ConsoleLink, ConsoleService};
use idle_head_core::driver::DriverConfig;
use idle_head_core::driver::DriverParams;
use idle_head_core::motion::HeadConfig;
use idle_head_core::seed::BoardId;
use idle_head_core::settings::SettingsStorage;
use portable_atomic::AtomicU32;
use static_cell::ConstStaticCell;

use crate::config::{Set, SetRef};
use crate::dmx::Receiver;
use crate::exchange::{Exchange, FirstSet};
use crate::log;
use crate::radar::Radar;
use crate::storage::FlashBusy;
pub use crate::storage::Loaded;

/// What the firmware's tasks share: one of these lives in [`LINKS`], and
/// each task is handed the part it needs (a host test makes its own).
pub struct Links {
    /// Actions from the console ports (and the inputs) to the frame task,
    /// which it drains between frames.
    pub commands: CommandQueue,
    /// Status, servo calibrations and seeds between the console and the
    /// frame task (and the loop generator).
    pub console: ConsoleLink,
    /// The show layer's inputs: the DMX receiver's cues and settings, the
    /// radar's sightings and a Bottango session's curves (receivers and
    /// console ports → frame task).
    pub show: ShowLink,
    /// The channels the loop set buffers go round through.
    pub exchange: Exchange,
    /// The latest a frame task woke after its deadline since boot, µs
    /// (for the status report).
    pub latest_wake_us: AtomicU32,
}

impl Links {
    /// Nothing shared yet.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            commands: CommandQueue::new(),
            console: ConsoleLink::new(),
            show: ShowLink::new(),
            exchange: Exchange::new(),
            latest_wake_us: AtomicU32::new(0),
        }
    }
}

impl Default for Links {
    fn default() -> Self {
        Self::new()
    }
}

/// The board's shared state, which [`boot`] sets up and hands on.
pub static LINKS: Links = Links::new();

/// The DMX receiver, for the board's UART interrupt: taken under a
/// critical section, borrowed with `try_borrow_mut` (never re-entered:
/// only that interrupt takes it).
pub static RECEIVER: Mutex<CriticalSectionRawMutex, RefCell<Receiver>> =
    Mutex::new(RefCell::new(Receiver::new()));

/// The radar's decoder, for the board's receiver ([`Radar::receive`]).
pub static RADAR: Radar = Radar::new();

/// Set while the settings store holds the flash: the board's store and its
/// frame hooks share it.
pub static FLASH_BUSY: FlashBusy = FlashBusy::new();

/// The two loop set buffers, 2 · 5.4 KB: one plays while the generator
/// fills the other. All zero (the neutral pose) until generated.
static SETS: ConstStaticCell<[Set; 2]> = ConstStaticCell::new([Set::new(), Set::new()]);

/// How a board times the boot precompute, and in what unit it logs it.
pub trait Stopwatch {
    /// Runs `work`, returning what it gave and how long it took in this
    /// stopwatch's unit.
    fn time<R>(&mut self, work: impl FnOnce() -> R) -> (R, u64);
    /// The unit, for the log (`"us"`, `"instructions"`).
    fn unit(&self) -> &'static str;
}

/// Times with embassy-time's clock, in microseconds.
pub struct Clock;

impl Stopwatch for Clock {
    fn time<R>(&mut self, work: impl FnOnce() -> R) -> (R, u64) {
        let start = Instant::now();
        let result = work();
        (result, start.elapsed().as_micros())
    }

    fn unit(&self) -> &'static str {
        "us"
    }
}

/// What the generator task starts from: the idle's configuration and the
/// two loop set buffers.
pub struct Generator {
    /// The idle's configuration, with the settings' seeds.
    pub head: HeadConfig,
    /// The buffer loop set 0 is generated into.
    pub first: SetRef,
    /// The other buffer.
    pub spare: SetRef,
    /// Where the sets go, and the console's seeds come from.
    pub links: &'static Links,
}

/// What the boot sequence hands the board's tasks.
pub struct Booted<S: 'static> {
    /// The loop generator's start (it generates loop set 0, which the frame
    /// task waits for, then each next set).
    pub generator: Generator,
    /// The driver's parameters of the settings in effect.
    pub driver: DriverParams,
    /// The behaviour's parameters of the settings in effect.
    pub behaviour: BehaviourParams,
    /// The console's service, on the board's storage.
    pub service: ConsoleService<'static, S>,
    /// What the tasks share ([`LINKS`]).
    pub links: &'static Links,
}

/// Why [`boot`] could not run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BootError {
    /// The loop set buffers were taken already: `boot` runs once.
    AlreadyBooted,
}

/// The boot sequence (see the [module docs](self)) on the board's driver
/// configuration `base`, with the settings `loaded`; `entropy` is mixed into
/// the console's `seed random`. A board with no unique id and none of the
/// optional parts (inputs, DMX, radar): see [`boot_on`] for the others.
///
/// # Errors
/// [`BootError::AlreadyBooted`] if called a second time.
pub fn boot<S: SettingsStorage>(
    base: &DriverConfig,
    loaded: Loaded<S>,
    entropy: u32,
) -> Result<Booted<S>, BootError> {
    boot_on(base, loaded, entropy, BoardId::NONE, BoardParts::NONE)
}

/// [`boot`] on a board whose unique id is `id` (the RP2040's flash unique
/// id, the RP2350's chip id; [`BoardId::NONE`] if it cannot read one): the
/// idle's seeds of `seed board`, the default, come from it. The console
/// answers for the board's `parts` (its inputs' numbers, DMX, radar) and
/// refuses the commands of those it lacks.
///
/// # Errors
/// [`BootError::AlreadyBooted`] if called a second time.
#[inline(never)]
pub fn boot_on<S: SettingsStorage>(
    base: &DriverConfig,
    loaded: Loaded<S>,
    entropy: u32,
    id: BoardId,
    parts: BoardParts,
) -> Result<Booted<S>, BootError> {
    log_servos(&loaded);
    let [first, spare] = SETS.try_take().ok_or(BootError::AlreadyBooted)?;
    let head = loaded.head(id);
    let links = &LINKS;
    // The input task reads its settings from the link.
    links.console.set_inputs(loaded.settings.inputs);
    let Loaded {
        storage,
        settings,
        source,
        valid,
    } = loaded;
    links.show.dmx.set(settings.dmx);
    links.show.track.set(settings.track);
    // `valid` is these settings checked with `base` (by the store, or at
    // compile time for the built-in ones): the service takes it as it is.
    let mut service = ConsoleService::checked(
        &links.commands,
        &links.console,
        storage,
        *base,
        settings,
        source,
        &valid,
    );
    service.add_entropy(entropy);
    let service = service
        .with_show(&links.show)
        .with_board(id)
        .with_parts(parts);
    Ok(Booted {
        generator: Generator {
            head,
            first,
            spare,
            links,
        },
        driver: valid.driver,
        behaviour: valid.behaviour,
        service,
        links,
    })
}

/// Generates loop set 0 of `head` into `first` and logs it (the generator
/// task's first step).
pub(crate) fn first_set(
    first: &mut Set,
    head: &HeadConfig,
    stopwatch: &mut impl Stopwatch,
) -> FirstSet {
    let (generated, precompute) = stopwatch.time(|| first.generate(head));
    let generated = match generated {
        Ok(info) => {
            for (axis, info) in Axis::ALL.iter().zip(info.iter()) {
                log::info!(
                    "{=str}: split at sample {=u16} (drawn from {=u16} zero crossings); {=u16} up-steps in the walk",
                    axis.name(),
                    info.split,
                    info.crossings,
                    info.up_steps
                );
            }
            true
        }
        // The loop is left at the neutral pose: the servos hold still.
        Err(e) => {
            log::error!(
                "trajectory generation failed: {=str} {=str}",
                e.axis.name(),
                e.error.message()
            );
            false
        }
    };
    let checksum = first.checksum();
    log::info!(
        "precompute: {=u64} {=str}; checksum {=u32:#010x}",
        precompute,
        stopwatch.unit(),
        checksum
    );
    FirstSet {
        checksum,
        generated,
        precompute,
    }
}

/// Logs each servo's calibration as the head starts with it.
fn log_servos<S>(loaded: &Loaded<S>) {
    for (axis, servo) in Axis::ALL.iter().zip(loaded.settings.servos.iter()) {
        log::info!(
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
