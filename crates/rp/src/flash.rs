//! The settings store in the board's flash: the last four 4 KiB erase
//! sectors (`SETTINGS` in the board's memory.x, which keeps code out of
//! them), on embassy-rp's flash driver in blocking mode, made async by
//! [`BlockingAsync`] (see `idle_head_firmware::storage`).

use core::ops::Range;

use embassy_embedded_hal::adapter::BlockingAsync;
use embassy_rp::Peri;
use embassy_rp::flash::{Blocking, ERASE_SIZE, Flash};
use embassy_rp::peripherals::FLASH;
use embassy_time::Duration;
use idle_head_core::driver::DriverConfig;
use idle_head_firmware::boot::Loaded;
use idle_head_firmware::storage::{self, FlashBusy, FlashStorage};
use static_cell::StaticCell;

/// The board's flash: the Raspberry Pi Pico's 2 MiB (W25Q16JV).
#[cfg(feature = "rp2040")]
pub const FLASH_SIZE: usize = 2 * 1024 * 1024;
/// The board's flash: the Raspberry Pi Pico 2's 4 MiB (W25Q32RV).
#[cfg(feature = "rp235xa")]
pub const FLASH_SIZE: usize = 4 * 1024 * 1024;

/// Erase sectors of the settings region.
const SECTORS: u32 = 4;
/// The settings region, offsets from the start of flash (as the driver
/// counts): the last [`SECTORS`] sectors. The memory map's `SETTINGS`
/// region; `cargo xtask test` checks that no code is linked there.
pub const SETTINGS_RANGE: Range<u32> = {
    let end = FLASH_SIZE as u32;
    let start = end - SECTORS * ERASE_SIZE as u32;
    start..end
};
/// Where the region appears in the address space (XIP base + offset).
pub const SETTINGS_ADDRESS: u32 = 0x1000_0000 + SETTINGS_RANGE.start;

/// The flash driver the store runs on.
pub type BoardFlash = BlockingAsync<Flash<'static, FLASH, Blocking, FLASH_SIZE>>;

/// The store on the board's flash, in a static of its own.
pub type Store = FlashStorage<BoardFlash>;

/// The console's `save` and `load` on the board's flash.
pub type Storage = &'static mut Store;

/// Where the store stays.
static STORE: StaticCell<Store> = StaticCell::new();

/// Opens the store and reads the settings the board boots with, checked
/// against `base` (see `idle_head_firmware::storage::open`); `feed` feeds
/// the watchdog before each flash operation, while `busy` is set. `None` if
/// called twice.
#[must_use]
#[inline(never)]
pub fn open(
    flash: Peri<'static, FLASH>,
    base: &DriverConfig,
    feed: fn(Duration),
    busy: &'static FlashBusy,
) -> Option<Loaded<Storage>> {
    let flash = BlockingAsync::new(Flash::new_blocking(flash));
    storage::open(
        &STORE,
        flash,
        SETTINGS_RANGE,
        SETTINGS_ADDRESS,
        base,
        feed,
        busy,
    )
}
