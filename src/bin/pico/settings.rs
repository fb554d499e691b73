//! The settings store in the Pico's flash: the last four 4 KiB erase
//! sectors, `0x101f_c000..0x1020_0000` (`SETTINGS` in memory.x, which keeps
//! code out of them), kept by `sequential-storage` through
//! [`SettingsStore`].
//!
//! The flash driver is embassy-rp's in blocking mode, made async by
//! [`BlockingAsync`]: reads are plain reads of the memory-mapped flash, and
//! an erase or a write runs from RAM with interrupts off, as the flash
//! cannot be read (nor code run from it) meanwhile. A sector erase takes
//! 45 ms typically (W25Q16JV, up to 400 ms), two frames or more: only the
//! boot probe touches the store today, before the first frame.
//!
//! At boot the store is opened and its record probed ([`probe`]); the
//! head runs on its built-in settings and the log says what the store
//! holds. Reading the record into the settings arrives with the settings
//! type; until then [`Probe`] stands in for it, a record that decodes
//! nothing.

use core::future::Future;
use core::ops::Range;
use core::pin::pin;
use core::task::{Context, Poll, Waker};

use embassy_embedded_hal::adapter::BlockingAsync;
use embassy_rp::Peri;
use embassy_rp::flash::{Blocking, ERASE_SIZE, Error as FlashError, Flash};
use embassy_rp::peripherals::FLASH;
use idle_head::settings::{DecodeError, EncodeError, LoadError, Record, SettingsStore};

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

/// The flash driver the store runs on.
pub type PicoFlash = BlockingAsync<Flash<'static, FLASH, Blocking, FLASH_SIZE>>;

/// The store, with a record of up to 125 bytes.
pub type Store<R> = SettingsStore<PicoFlash, R, 128>;

/// A stand-in record that reads nothing: any record saved by a firmware
/// with settings has a lower version, so a probe tells an empty store
/// from a damaged one and finds the stored version, without a settings
/// type.
pub struct Probe;

impl Record for Probe {
    const VERSION: u16 = u16::MAX;

    fn encode(&self, _: &mut [u8]) -> Result<usize, EncodeError> {
        Err(EncodeError::Unsupported)
    }

    fn decode(_: &[u8]) -> Result<Self, DecodeError> {
        Err(DecodeError::Malformed)
    }
}

/// Opens the store on the flash peripheral. `None` (logged) if the region
/// is not a valid store range, which `SETTINGS_RANGE` rules out.
fn open<R: Record>(flash: Peri<'static, FLASH>) -> Option<Store<R>> {
    let flash = BlockingAsync::new(Flash::new_blocking(flash));
    match Store::new(flash, SETTINGS_RANGE) {
        Ok(store) => Some(store),
        Err(_) => {
            defmt::error!("settings: no store: the region is not whole erase sectors");
            None
        }
    }
}

/// Opens the store on the flash peripheral, reads what it holds and logs
/// it: the head runs on its built-in settings whatever it finds.
///
/// The store and its buffer live on the stack for this call only (at boot,
/// before the loop generator's deeper stack), not in the main task's
/// static state.
pub fn probe(flash: Peri<'static, FLASH>) {
    let Some(mut store) = open::<Probe>(flash) else {
        return;
    };
    match at_once(store.load()) {
        Some(loaded) => log(loaded),
        None => defmt::error!("settings: the blocking flash driver waited"),
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

fn log(loaded: Result<Probe, LoadError<FlashError>>) {
    let at = SETTINGS_ADDRESS;
    match loaded {
        Err(LoadError::Empty) => {
            defmt::info!("settings: defaults (empty store at {=u32:#010x})", at);
        }
        Err(LoadError::Older { found }) => defmt::info!(
            "settings: defaults; the store at {=u32:#010x} holds a record of version {=u16}, read once the settings service is in",
            at,
            found
        ),
        Err(LoadError::Flash(e)) => warn_flash(at, e),
        Err(LoadError::Corrupt | LoadError::Newer { .. } | LoadError::Invalid) | Ok(Probe) => {
            defmt::warn!(
                "settings: defaults; the store at {=u32:#010x} is damaged",
                at
            );
        }
    }
}

fn warn_flash(at: u32, e: FlashError) {
    defmt::warn!(
        "settings: defaults; reading the store at {=u32:#010x} failed: {}",
        at,
        e
    );
}
