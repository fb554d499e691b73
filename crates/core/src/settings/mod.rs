//! Settings kept in flash: one versioned record, written so that a power
//! cut at any moment leaves the old record or the new one, never a mix.
//!
//! - [`Record`]: how a settings type turns into bytes and back, with the
//!   version of that layout. With the `postcard` feature,
//!   [`encode_postcard`] and [`decode_postcard`] do it for any serde type.
//! - [`Settings`]: the head's settings (servos, behaviour, seeds), one
//!   validated record of version 1 ([`Settings::DEFAULT`]: the built-in
//!   configuration).
//! - [`SettingsStorage`]: what the console's `save` and `load` call, a
//!   trait each board implements; [`RamStorage`] keeps the record in RAM.
//! - [`SettingsStore`]: the record in a range of NOR flash (anything that
//!   implements `embedded_storage_async::nor_flash::NorFlash`, such as
//!   embassy-rp's flash driver), kept by `sequential-storage`'s map.
//!
//! **Why a power cut cannot mix two records.** A save appends a new item
//! (header with a CRC-32 of the data, then the data) after the old one
//! and never overwrites it in place; a load returns the newest item whose
//! CRC matches. Cut before the new item is complete and its CRC fails, so
//! the old item is found; once it is complete, it is the new record. When
//! a page fills up, the newest items move to the next page before the old
//! page is erased, and an interrupted move is repaired on the next access.
//! The host tests cut the power at every byte of many saves in a row.
//!
//! **Damage.** An item whose CRC fails is skipped, so a damaged newest
//! record loads as the one saved before it, or as
//! [`LoadError::Empty`] if none is left; damage the map cannot repair is
//! [`LoadError::Corrupt`]. A load never returns bytes that were not saved
//! as a record. A save reads its record back and writes it again past a
//! damaged spot if needed.
//!
//! `sequential-storage` indexes and unwraps internally, so loading and
//! saving are not free of panic paths; they run at boot and on `save` or
//! `load`, never on the frame path.

mod codec;
mod record;
mod sectors;
mod storage;
mod store;
mod values;

pub use codec::SETTINGS_LEN;
pub use record::{DecodeError, EncodeError, RawRecord, Record};
#[cfg(feature = "postcard")]
pub use record::{decode_postcard, encode_postcard};
pub use sectors::SectorWise;
pub use sequential_storage::map::MapConfigError;
pub use storage::{RamStorage, SettingsStorage, StorageError};
pub use store::{LoadError, SaveError, SettingsStore, buffer_len};
pub use values::{Settings, SettingsError, SettingsSource, Validated};

/// The work buffer of a store of [`Settings`] (see [`buffer_len`]).
pub const SETTINGS_BUFFER: usize = buffer_len(SETTINGS_LEN);
