//! The settings store in a board's flash: a range of whole erase sectors
//! that the board's memory map keeps code out of, kept by
//! `sequential-storage` through [`SettingsStore`].
//!
//! At boot ([`open`]) the store is read before the first frame and the
//! settings it holds are put in effect (or the built-in ones, with a
//! warning, if it holds none that can be used). The console's `save` and
//! `load` go through [`FlashStorage`], which feeds the watchdog the long
//! [`FLASH_WATCHDOG_MS`] before every flash operation and sets
//! [`FlashBusy`] meanwhile (the frames feed the long timeout too); erases
//! go one sector at a time ([`SectorWise`]).
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The settings store in flash”).

use core::future::Future;
use core::ops::Range;
use core::pin::pin;
use core::sync::atomic::{AtomicBool, Ordering};
use core::task::{Context, Poll, Waker};

use embassy_time::Duration;
use embedded_storage_async::nor_flash::NorFlash;
use idle_head_core::driver::DriverConfig;
use idle_head_core::motion::{DEFAULT_HEAD, HeadConfig};
use idle_head_core::seed::BoardId;
use idle_head_core::settings::{
    FlashFailed, Loaded as Stored, Record, SETTINGS_BUFFER, SectorWise, Settings, SettingsError,
    SettingsSource, SettingsStorage, SettingsStore, StorageError, Validated,
};

use static_cell::StaticCell;

use crate::log::{self, Loggable};

/// The watchdog timeout the frames feed while a flash operation is under
/// way: a 400 ms sector erase, with a wide margin.
pub const FLASH_WATCHDOG_MS: u64 = 1000;

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
            valid: Validated::DEFAULT,
        }
    }

    /// The idle motion's configuration with these settings' seeds on a
    /// board of `id` (see `idle_head_core::seed`).
    #[must_use]
    pub const fn head(&self, id: BoardId) -> HeadConfig {
        let seeds = self.settings.idle_seeds(id);
        let mut head = DEFAULT_HEAD;
        head.pitch.seed = seeds[0];
        head.roll.seed = seeds[1];
        head.yaw.seed = seeds[2];
        head
    }
}

/// Whether `save` or `load` uses the flash: while it does, the frames
/// feed the watchdog with [`FLASH_WATCHDOG_MS`] (see the [module
/// docs](self)). One lives in [`FLASH_BUSY`](crate::boot::FLASH_BUSY).
pub struct FlashBusy(AtomicBool);

impl FlashBusy {
    /// Not busy.
    #[must_use]
    pub const fn new() -> Self {
        Self(AtomicBool::new(false))
    }

    /// Whether the flash is in use.
    pub fn is_busy(&self) -> bool {
        self.0.load(Ordering::Acquire)
    }

    /// The watchdog timeout the frames feed: `normal`, or
    /// [`FLASH_WATCHDOG_MS`] while the flash is in use.
    pub fn timeout(&self, normal: Duration) -> Duration {
        if self.is_busy() {
            Duration::from_millis(FLASH_WATCHDOG_MS)
        } else {
            normal
        }
    }

    fn set(&self, busy: bool) {
        self.0.store(busy, Ordering::Release);
    }
}

impl Default for FlashBusy {
    fn default() -> Self {
        Self::new()
    }
}

/// The store on flash driver `F`, with a work buffer for the settings
/// record; erases go one sector at a time.
pub type Store<F> = SettingsStore<SectorWise<F>, Settings, SETTINGS_BUFFER>;

/// The console's `save` and `load` on the flash store.
pub struct FlashStorage<F: NorFlash> {
    /// `None` if the store could not be opened (logged at boot).
    store: Option<Store<F>>,
    /// Feeds the board's watchdog for a timeout.
    feed: fn(Duration),
    /// Set while an operation runs.
    busy: &'static FlashBusy,
}

impl<F: NorFlash> FlashStorage<F> {
    /// Runs `op` on the store with the watchdog's flash timeout in force
    /// (see the [module docs](self)).
    fn guarded<T>(
        &mut self,
        op: impl FnOnce(&mut Store<F>) -> Result<T, StorageError>,
    ) -> Result<T, StorageError> {
        let store = self
            .store
            .as_mut()
            .ok_or(StorageError::Flash(FlashFailed))?;
        self.busy.set(true);
        // A frame from here on feeds the long timeout too.
        (self.feed)(Duration::from_millis(FLASH_WATCHDOG_MS));
        let result = op(store);
        self.busy.set(false);
        result
    }
}

impl<F: NorFlash> SettingsStorage for FlashStorage<F> {
    fn save(&mut self, settings: &Settings) -> Result<(), StorageError> {
        self.guarded(|store| match at_once(store.save(settings)) {
            Some(result) => result.map_err(StorageError::from),
            None => Err(StorageError::Flash(FlashFailed)),
        })
    }

    fn load(&mut self) -> Result<Settings, StorageError> {
        self.guarded(|store| match at_once(store.load()) {
            Some(result) => result
                .map(|loaded| loaded.record)
                .map_err(StorageError::forget_flash),
            None => Err(StorageError::Flash(FlashFailed)),
        })
    }
}

/// Opens the store on `flash` in `range` (offsets as the driver counts,
/// whole erase sectors; `address` is where the range appears in the address
/// space, for the log) in `cell`, where it stays (the console saves through
/// it), and reads the settings in it, before the first frame (no watchdog,
/// no frames yet), checked against `base`; the built-in settings if there
/// are none or they are not usable. The log says which. `feed` feeds the
/// board's watchdog before each later flash operation, and `busy` tells
/// the frames that it runs. The console's storage is `S` made from the
/// store (the store itself, or `Some(store)` for a board's optional one,
/// made here so that the settings are not copied again on the way).
/// `None` if `cell` was taken.
pub fn open<F, S>(
    cell: &'static StaticCell<FlashStorage<F>>,
    flash: F,
    range: Range<u32>,
    address: u32,
    base: &DriverConfig,
    feed: fn(Duration),
    busy: &'static FlashBusy,
) -> Option<Loaded<S>>
where
    F: NorFlash,
    F::Error: Loggable,
    S: From<&'static mut FlashStorage<F>>,
{
    let store = Store::new(SectorWise(flash), range).ok();
    if store.is_none() {
        log::error!("settings: no store: the region is not whole erase sectors");
    }
    let storage = cell.try_init(FlashStorage { store, feed, busy })?;
    let loaded = storage.store.as_mut().and_then(|store| {
        let loaded = at_once(store.load());
        if loaded.is_none() {
            log::error!("settings: defaults; the blocking flash driver waited");
        }
        loaded.and_then(|loaded| loaded_settings(loaded, base, address))
    });
    let storage = S::from(storage);
    Some(match loaded {
        Some((settings, valid)) => Loaded {
            storage,
            settings,
            source: SettingsSource::Flash,
            valid,
        },
        None => Loaded::defaults(storage),
    })
}

/// Polls `future` once: every flash operation of the boards' drivers is blocking
/// underneath, so the store's futures complete on their first poll. Always
/// inline: the future is built in its caller's frame and polled there, not
/// copied into a frame of its own (half a kilobyte of the boot's stack).
#[allow(clippy::inline_always)]
#[inline(always)]
fn at_once<F: Future>(future: F) -> Option<F::Output> {
    match pin!(future).poll(&mut Context::from_waker(Waker::noop())) {
        Poll::Ready(output) => Some(output),
        Poll::Pending => None,
    }
}

/// The stored settings if they can be used with `base`, logged either way.
// defmt keeps each text in a symbol of its own: arms that differ in their
// text alone look the same to clippy.
#[allow(clippy::match_same_arms)]
fn loaded_settings<E: Loggable>(
    loaded: Result<Stored<Settings>, StorageError<E, SettingsError>>,
    base: &DriverConfig,
    at: u32,
) -> Option<(Settings, Validated)> {
    match loaded {
        Ok(Stored {
            record: settings,
            version,
            fields,
        }) => match settings.validate(base) {
            Ok(valid) => {
                log::info!(
                    "settings: loaded from flash (version {=u16}) at {=u32:#010x}",
                    version,
                    at
                );
                if version != Settings::VERSION {
                    log::info!(
                        "settings: migrated from version {=u16} to {=u16}",
                        version,
                        Settings::VERSION
                    );
                }
                if !fields.missing.is_empty() {
                    log::info!(
                        "settings: fields not in the stored record, on their defaults: {}",
                        fields.missing
                    );
                }
                if !fields.unknown.is_empty() {
                    log::warn!(
                        "settings: fields of a newer firmware skipped (a save leaves them out): {}",
                        fields.unknown
                    );
                }
                if !fields.rejected.is_empty() {
                    log::warn!(
                        "settings: fields with values out of range, on their defaults: {}",
                        fields.rejected
                    );
                }
                return Some((settings, valid));
            }
            Err(e) => log::warn!(
                "settings: defaults; the stored settings fail validation: {}",
                e
            ),
        },
        // (A store never reports itself absent: only a board's `None` does.)
        Err(StorageError::Empty | StorageError::Absent) => {
            log::info!("settings: defaults (empty store at {=u32:#010x})", at);
        }
        Err(StorageError::Older { found } | StorageError::Newer { found }) => log::warn!(
            "settings: defaults; the store at {=u32:#010x} holds settings of version {=u16}, not {=u16}",
            at,
            found,
            Settings::VERSION
        ),
        Err(StorageError::TooLong { needs: Some(needs) }) => log::warn!(
            "settings: defaults; the record at {=u32:#010x} needs {=usize} B, more than this firmware reads",
            at,
            needs
        ),
        Err(StorageError::TooLong { needs: None }) => log::warn!(
            "settings: defaults; the record at {=u32:#010x} is longer than this firmware reads",
            at
        ),
        Err(StorageError::Invalid(e)) => log::warn!(
            "settings: defaults; the stored settings fail validation: {}",
            e
        ),
        Err(StorageError::Flash(e)) => log::warn!(
            "settings: defaults; reading the store at {=u32:#010x} failed: {}",
            at,
            e
        ),
        Err(StorageError::Corrupt) => log::warn!(
            "settings: defaults; the store at {=u32:#010x} is damaged",
            at
        ),
    }
    None
}

#[cfg(test)]
mod tests;
