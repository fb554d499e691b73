//! The settings store in the board's flash: the last four 4 KiB erase
//! sectors (`SETTINGS` in the board's memory.x, which keeps code out of
//! them), on embassy-rp's flash driver in blocking mode, made async by
//! [`BlockingAsync`] (see `idle_head_firmware::storage`). Before the store
//! opens, at boot when nothing else runs, the board's unique id is read:
//! the flash chip's on the Pico (the RP2040 has none of its own), the
//! chip id in OTP on the Pico 2.

use core::ops::Range;

use embassy_embedded_hal::adapter::BlockingAsync;
use embassy_rp::Peri;
use embassy_rp::flash::{Blocking, ERASE_SIZE, Flash};
use embassy_rp::peripherals::FLASH;
use embassy_time::Duration;
use idle_head_core::driver::DriverConfig;
use idle_head_core::seed::BoardId;
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

/// The console's `save` and `load` on the board's flash (`None` on a board
/// without a settings store: `err unavailable`).
pub type Storage = Option<&'static mut Store>;

/// Where the store stays.
static STORE: StaticCell<Store> = StaticCell::new();

/// Reads the board's unique id, then opens the store and reads the
/// settings the board boots with, checked against `base` (see
/// `idle_head_firmware::storage::open`); `feed` feeds the watchdog before
/// each flash operation, while `busy` is set. `None` if called twice.
#[must_use]
#[inline(never)]
pub fn open(
    flash: Peri<'static, FLASH>,
    base: &DriverConfig,
    feed: fn(Duration),
    busy: &'static FlashBusy,
) -> Option<(Loaded<Storage>, BoardId)> {
    let mut flash = Flash::new_blocking(flash);
    let id = unique_id(&mut flash);
    let flash = BlockingAsync::new(flash);
    let loaded = storage::open(
        &STORE,
        flash,
        SETTINGS_RANGE,
        SETTINGS_ADDRESS,
        base,
        feed,
        busy,
    )?;
    Some((loaded, id))
}

/// The flash chip's 64-bit unique id (command 4Bh, the W25Q16JV's; the
/// boot ROM's flash functions around it, interrupts off for the few µs it
/// takes), in the order the chip sends it; [`BoardId::NONE`] if it cannot
/// be read. A flash without the command answers all ones: no id either.
#[cfg(feature = "rp2040")]
fn unique_id(flash: &mut Flash<'static, FLASH, Blocking, FLASH_SIZE>) -> BoardId {
    let mut id = [0; 8];
    match flash.blocking_unique_id(&mut id) {
        Ok(()) => BoardId(u64::from_be_bytes(id)),
        Err(_) => BoardId::NONE,
    }
}

/// The RP2350's 64-bit chip id, from OTP rows 0 to 3; [`BoardId::NONE`] if
/// it cannot be read.
#[cfg(feature = "rp235xa")]
fn unique_id(_: &mut Flash<'static, FLASH, Blocking, FLASH_SIZE>) -> BoardId {
    embassy_rp::otp::get_chipid().map_or(BoardId::NONE, BoardId)
}
