//! The settings store in the Pico's flash: the last four 4 KiB erase
//! sectors, `0x101f_c000..0x1020_0000` (`SETTINGS` in memory.x, which keeps
//! code out of them), kept by `sequential-storage` through
//! [`SettingsStore`].
//!
//! The flash driver is embassy-rp's in blocking mode, made async by
//! [`BlockingAsync`]: reads are plain reads of the memory-mapped flash, and
//! an erase or a write runs from RAM with interrupts off, as the flash
//! cannot be read (nor code run from it) meanwhile. [`SectorWise`] splits
//! every erase into one call per sector, so the interrupts come back (and a
//! due frame runs) between sectors.
//!
//! At boot ([`boot`]) the store is read before the first frame: stored
//! settings are put in effect (servo calibrations, behaviour, seeds) and
//! logged with their version (an older layout is migrated), with the
//! fields the load skipped or left on their defaults; an empty store gives
//! the built-in settings; a damaged store, or one of a version this
//! firmware cannot read, gives the built-in settings with a warning. The console's `save` and
//! `load` go through [`PicoStorage`].
//!
//! # `save` and the watchdog
//!
//! A sector erase takes 45 ms typically (W25Q16JV), up to 400 ms, with
//! interrupts off: no frame runs meanwhile, and the watchdog (100 ms) would
//! reset the board. So around every flash operation of `save` and `load`
//! [`PicoStorage`] sets [`FLASH_BUSY`] and waits (at most
//! [`FRAME_WAIT_MS`]) for one frame: that frame, and every frame until the
//! operation ends, feeds the watchdog with [`FLASH_WATCHDOG_MS`] instead of
//! 100 ms. Afterwards the next frame feeds it with 100 ms again. While the
//! interrupts are off the PWM hardware keeps sending the last pulses, so
//! the servos hold their pose; the frames due meanwhile are missed (the
//! frame task's lateness shows it), and the head resumes where its clock
//! stands. An erase of several sectors (the whole store, when a damaged one
//! is started afresh) goes one sector at a time ([`SectorWise`]): the
//! interrupts are never off for more than one sector.

use core::future::Future;
use core::ops::Range;
use core::pin::pin;
use core::sync::atomic::{AtomicBool, Ordering};
use core::task::{Context, Poll, Waker};

use embassy_embedded_hal::adapter::BlockingAsync;
use embassy_rp::Peri;
use embassy_rp::flash::{Blocking, ERASE_SIZE, Error as FlashError, Flash};
use embassy_rp::peripherals::FLASH;
use embassy_time::{Duration, Instant};
use idle_head_core::console::ConsoleLink;
use idle_head_core::driver::DriverConfig;
use idle_head_core::motion::{DEFAULT_HEAD, HeadConfig};
use idle_head_core::settings::{
    LoadError, Loaded, Record, SETTINGS_BUFFER, SectorWise, Settings, SettingsError,
    SettingsSource, SettingsStorage, SettingsStore, StorageError, Validated,
};

/// The Pico's flash: 2 MiB (W25Q16JV).
pub const FLASH_SIZE: usize = 2 * 1024 * 1024;
/// Erase sectors of the settings region.
const SECTORS: u32 = 4;
/// The settings region, offsets from the start of flash (as the driver
/// counts): the last [`SECTORS`] sectors. memory.x's `SETTINGS` region.
pub const SETTINGS_RANGE: Range<u32> = {
    let end = FLASH_SIZE as u32;
    let start = end - SECTORS * ERASE_SIZE as u32;
    start..end
};
/// Where the region appears in the address space (XIP base + offset).
pub const SETTINGS_ADDRESS: u32 = 0x1000_0000 + SETTINGS_RANGE.start;
// memory.x reserves the same sectors (`SETTINGS`); `cargo xtask test`
// checks that no code is linked there.
const _: () = assert!(SETTINGS_ADDRESS == 0x101f_c000);

/// The watchdog timeout the frames feed while a flash operation is under
/// way: a 400 ms sector erase, with a wide margin.
pub const FLASH_WATCHDOG_MS: u64 = 1000;
/// How long a flash operation waits for the frame that feeds the watchdog
/// with [`FLASH_WATCHDOG_MS`]: more than a frame (20 ms).
pub const FRAME_WAIT_MS: u64 = 50;

/// Set while `save` or `load` uses the flash: the frames feed the watchdog
/// with [`FLASH_WATCHDOG_MS`] (see the [module docs](self)).
pub static FLASH_BUSY: AtomicBool = AtomicBool::new(false);

/// The flash driver the store runs on.
pub type PicoFlash = SectorWise<BlockingAsync<Flash<'static, FLASH, Blocking, FLASH_SIZE>>>;

/// The store, with a work buffer for the settings record.
pub type Store = SettingsStore<PicoFlash, Settings, SETTINGS_BUFFER>;

/// The console's `save` and `load` on the flash store.
pub struct PicoStorage {
    /// `None` if the store could not be opened (logged at boot).
    store: Option<Store>,
    /// The frame task's status, to see a frame pass.
    link: &'static ConsoleLink,
}

impl PicoStorage {
    /// Runs `op` on the store with the watchdog's flash timeout in force.
    fn guarded<T>(
        &mut self,
        op: impl FnOnce(&mut Store) -> Result<T, StorageError>,
    ) -> Result<T, StorageError> {
        let store = self.store.as_mut().ok_or(StorageError::Device)?;
        FLASH_BUSY.store(true, Ordering::Release);
        // The frame task runs above this task: once the frame count moves,
        // that frame has fed the watchdog with the long timeout. If no frame
        // comes (the watchdog is not running yet), go on.
        let frame = self.link.status().frame;
        let since = Instant::now();
        while self.link.status().frame == frame
            && since.elapsed() < Duration::from_millis(FRAME_WAIT_MS)
        {
            core::hint::spin_loop();
        }
        let result = op(store);
        FLASH_BUSY.store(false, Ordering::Release);
        result
    }
}

impl SettingsStorage for PicoStorage {
    fn save(&mut self, settings: &Settings) -> Result<(), StorageError> {
        self.guarded(|store| match at_once(store.save(settings)) {
            Some(result) => result.map_err(StorageError::from),
            None => Err(StorageError::Device),
        })
    }

    fn load(&mut self) -> Result<Settings, StorageError> {
        self.guarded(|store| match at_once(store.load()) {
            Some(result) => result
                .map(|loaded| loaded.record)
                .map_err(StorageError::from),
            None => Err(StorageError::Device),
        })
    }
}

/// The settings the board boots with.
pub struct Boot {
    /// The console's store.
    pub storage: PicoStorage,
    /// The settings in effect.
    pub settings: Settings,
    /// Where they came from.
    pub source: SettingsSource,
    /// Their parameters for the driver and the behaviour.
    pub valid: Validated,
}

impl Boot {
    /// The idle motion's configuration with these settings' seeds.
    pub const fn head(&self) -> HeadConfig {
        let mut head = DEFAULT_HEAD;
        head.pitch.seed = self.settings.seeds[0];
        head.roll.seed = self.settings.seeds[1];
        head.yaw.seed = self.settings.seeds[2];
        head
    }
}

/// Opens the store on the flash peripheral and reads the settings in it
/// (before the first frame: no watchdog, no frames yet), checked against
/// `base`; the built-in settings (`defaults`, checked with `base` at compile
/// time) if there are none or they are not usable. The log says which.
pub fn boot(
    flash: Peri<'static, FLASH>,
    base: &DriverConfig,
    defaults: Validated,
    link: &'static ConsoleLink,
) -> Boot {
    let mut store = open(flash);
    let loaded = match store.as_mut() {
        Some(store) => match at_once(store.load()) {
            Some(loaded) => loaded_settings(loaded, base),
            None => {
                defmt::error!("settings: defaults; the blocking flash driver waited");
                None
            }
        },
        None => None,
    };
    let storage = PicoStorage { store, link };
    match loaded {
        Some((settings, valid)) => Boot {
            storage,
            settings,
            source: SettingsSource::Flash,
            valid,
        },
        None => Boot {
            storage,
            settings: Settings::DEFAULT,
            source: SettingsSource::Defaults,
            valid: defaults,
        },
    }
}

/// Opens the store. `None` (logged) if the region is not a valid store
/// range, which `SETTINGS_RANGE` rules out.
fn open(flash: Peri<'static, FLASH>) -> Option<Store> {
    let flash = SectorWise(BlockingAsync::new(Flash::new_blocking(flash)));
    match Store::new(flash, SETTINGS_RANGE) {
        Ok(store) => Some(store),
        Err(_) => {
            defmt::error!("settings: no store: the region is not whole erase sectors");
            None
        }
    }
}

/// Polls `future` once: every flash operation of [`PicoFlash`] is blocking
/// underneath, so the store's futures complete on their first poll.
fn at_once<F: Future>(future: F) -> Option<F::Output> {
    match pin!(future).poll(&mut Context::from_waker(Waker::noop())) {
        Poll::Ready(output) => Some(output),
        Poll::Pending => None,
    }
}

/// The stored settings if they can be used with `base`, logged either way.
fn loaded_settings(
    loaded: Result<Loaded<Settings>, LoadError<FlashError, SettingsError>>,
    base: &DriverConfig,
) -> Option<(Settings, Validated)> {
    let at = SETTINGS_ADDRESS;
    match loaded {
        Ok(Loaded {
            record: settings,
            version,
            fields,
        }) => match settings.validate(base) {
            Ok(valid) => {
                defmt::info!(
                    "settings: loaded from flash (version {=u16}) at {=u32:#010x}",
                    version,
                    at
                );
                if version != Settings::VERSION {
                    defmt::info!(
                        "settings: migrated from version {=u16} to {=u16}",
                        version,
                        Settings::VERSION
                    );
                }
                if !fields.missing.is_empty() {
                    defmt::info!(
                        "settings: fields not in the stored record, on their defaults: {}",
                        fields.missing
                    );
                }
                if !fields.unknown.is_empty() {
                    defmt::warn!(
                        "settings: fields of a newer firmware skipped (a save leaves them out): {}",
                        fields.unknown
                    );
                }
                if !fields.rejected.is_empty() {
                    defmt::warn!(
                        "settings: fields with values out of range, on their defaults: {}",
                        fields.rejected
                    );
                }
                return Some((settings, valid));
            }
            Err(e) => defmt::warn!(
                "settings: defaults; the stored settings fail validation: {}",
                e
            ),
        },
        Err(LoadError::Empty) => {
            defmt::info!("settings: defaults (empty store at {=u32:#010x})", at);
        }
        Err(LoadError::Older { found } | LoadError::Newer { found }) => defmt::warn!(
            "settings: defaults; the store at {=u32:#010x} holds settings of version {=u16}, not {=u16}",
            at,
            found,
            Settings::VERSION
        ),
        Err(LoadError::TooLong { needs }) => defmt::warn!(
            "settings: defaults; the record at {=u32:#010x} needs {=usize} B, more than this firmware reads",
            at,
            needs
        ),
        Err(LoadError::Invalid(e)) => defmt::warn!(
            "settings: defaults; the stored settings fail validation: {}",
            e
        ),
        Err(LoadError::Flash(e)) => defmt::warn!(
            "settings: defaults; reading the store at {=u32:#010x} failed: {}",
            at,
            e
        ),
        Err(LoadError::Corrupt) => defmt::warn!(
            "settings: defaults; the store at {=u32:#010x} is damaged",
            at
        ),
    }
    None
}
