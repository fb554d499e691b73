//! The settings store's guard: the watchdog's long timeout fed before a
//! `save` or `load` touches the flash, the frames told so while it does,
//! and the normal timeout back after it, whatever the outcome.

use std::cell::RefCell;

use embassy_time::Duration;
use embedded_storage_async::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use idle_head_core::driver::DriverConfig;
use idle_head_core::settings::{
    FlashFailed, Settings, SettingsSource, SettingsStorage, StorageError,
};
use static_cell::StaticCell;

use super::{FLASH_WATCHDOG_MS, FlashBusy, FlashStorage, open};
use crate::hooks::WATCHDOG_TIMEOUT;

const SECTOR: usize = 4096;
const SECTORS: usize = 4;

/// What happened, in order: a watchdog feed (its timeout, ms) or a flash
/// operation (whether the frames were told the flash is busy then).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Event {
    Fed(u64),
    Flash(bool),
}

thread_local! {
    static EVENTS: RefCell<Vec<Event>> = const { RefCell::new(Vec::new()) };
}

fn events() -> Vec<Event> {
    EVENTS.with(|e| e.borrow_mut().drain(..).collect())
}

/// The board's watchdog feed.
fn feed(timeout: Duration) {
    EVENTS.with(|e| e.borrow_mut().push(Event::Fed(timeout.as_millis())));
}

/// A NOR flash in RAM that notes whether the flash was flagged busy at
/// each operation; it fails every operation once `broken`.
struct Flash {
    bytes: Vec<u8>,
    busy: &'static FlashBusy,
    broken: bool,
}

#[derive(Debug)]
struct Broken;

impl NorFlashError for Broken {
    fn kind(&self) -> NorFlashErrorKind {
        NorFlashErrorKind::Other
    }
}

impl Flash {
    fn op(&self) -> Result<(), Broken> {
        EVENTS.with(|e| e.borrow_mut().push(Event::Flash(self.busy.is_busy())));
        if self.broken { Err(Broken) } else { Ok(()) }
    }
}

impl ErrorType for Flash {
    type Error = Broken;
}

impl ReadNorFlash for Flash {
    const READ_SIZE: usize = 1;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Broken> {
        self.op()?;
        let at = offset as usize;
        bytes.copy_from_slice(&self.bytes[at..at + bytes.len()]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.bytes.len()
    }
}

impl NorFlash for Flash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = SECTOR;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Broken> {
        self.op()?;
        self.bytes[from as usize..to as usize].fill(0xff);
        Ok(())
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Broken> {
        self.op()?;
        let at = offset as usize;
        for (cell, b) in self.bytes[at..at + bytes.len()].iter_mut().zip(bytes) {
            *cell &= *b;
        }
        Ok(())
    }
}

/// The store opened on an erased flash of `range`, as a board opens it at
/// boot; its busy flag.
fn opened(range: core::ops::Range<u32>) -> (&'static mut FlashStorage<Flash>, &'static FlashBusy) {
    let busy: &'static FlashBusy = Box::leak(Box::new(FlashBusy::new()));
    let cell: &'static StaticCell<FlashStorage<Flash>> = Box::leak(Box::new(StaticCell::new()));
    let flash = Flash {
        bytes: vec![0xff; SECTOR * SECTORS],
        busy,
        broken: false,
    };
    let loaded =
        open(cell, flash, range, 0, &DriverConfig::DEFAULT, feed, busy).expect("the cell is free");
    assert_eq!(loaded.source, SettingsSource::Defaults, "an empty store");
    (loaded.storage, busy)
}

const WHOLE: core::ops::Range<u32> = 0..(SECTOR * SECTORS) as u32;

/// The events of one operation: fed with the long timeout first, every
/// flash operation flagged busy.
fn assert_guarded(events: &[Event]) {
    assert_eq!(events.first(), Some(&Event::Fed(FLASH_WATCHDOG_MS)));
    let flash = &events[1..];
    assert!(!flash.is_empty(), "the flash was used");
    assert!(
        flash.iter().all(|e| *e == Event::Flash(true)),
        "every flash operation under the long timeout: {events:?}"
    );
}

#[test]
fn the_boots_read_is_not_guarded() {
    let (_, busy) = opened(WHOLE);
    let boot = events();
    // No watchdog runs yet at boot: nothing fed, nothing flagged.
    assert!(!boot.is_empty());
    assert!(boot.iter().all(|e| *e == Event::Flash(false)), "{boot:?}");
    assert!(!busy.is_busy());
}

#[test]
fn a_save_and_a_load_run_under_the_long_timeout_and_restore_the_normal_one() {
    let (storage, busy) = opened(WHOLE);
    let _ = events();
    let mut settings = Settings::DEFAULT;
    settings.seeds = [1, 2, 3];
    storage.save(&settings).expect("saved");
    assert_guarded(&events());
    assert!(!busy.is_busy());
    assert_eq!(busy.timeout(WATCHDOG_TIMEOUT), WATCHDOG_TIMEOUT);

    assert_eq!(storage.load(), Ok(settings));
    assert_guarded(&events());
    assert!(!busy.is_busy());
}

#[test]
fn the_frames_feed_the_long_timeout_while_the_flash_is_busy() {
    let busy = FlashBusy::new();
    assert_eq!(busy.timeout(WATCHDOG_TIMEOUT), WATCHDOG_TIMEOUT);
    busy.set(true);
    assert_eq!(
        busy.timeout(WATCHDOG_TIMEOUT),
        Duration::from_millis(FLASH_WATCHDOG_MS)
    );
    busy.set(false);
    assert_eq!(busy.timeout(WATCHDOG_TIMEOUT), WATCHDOG_TIMEOUT);
}

#[test]
fn a_failing_flash_still_restores_the_normal_timeout() {
    let (storage, busy) = opened(WHOLE);
    let _ = events();
    storage.store.as_mut().unwrap().flash().0.broken = true;
    assert_eq!(
        storage.save(&Settings::DEFAULT),
        Err(StorageError::Flash(FlashFailed))
    );
    assert_guarded(&events());
    assert!(!busy.is_busy());
    assert!(storage.load().is_err());
    assert!(!busy.is_busy());
}

#[test]
fn no_store_is_a_device_error_without_touching_the_watchdog() {
    // A range of part of a sector: no store.
    let (storage, busy) = opened(0..100);
    let _ = events();
    assert_eq!(
        storage.save(&Settings::DEFAULT),
        Err(StorageError::Flash(FlashFailed))
    );
    assert_eq!(storage.load(), Err(StorageError::Flash(FlashFailed)));
    assert_eq!(events(), []);
    assert!(!busy.is_busy());
}
