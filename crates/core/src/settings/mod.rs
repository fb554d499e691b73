//! Settings kept in flash: one record of tagged fields, written so that a
//! power cut at any moment leaves the old record or the new one, never a
//! mix, and read so that a firmware update keeps them.
//!
//! - [`Settings`]: the head's settings, its fields listed in [`FIELDS`]
//!   (`fields.rs`: one row per field, its id never reused).
//! - [`Record`]: a settings type as bytes and back, with its layout version.
//! - [`SettingsStorage`]: the console's `save` and `load`, which each board
//!   implements; [`RamStorage`] keeps the record in RAM.
//! - [`SettingsStore`]: the record in NOR flash, over `sequential-storage`.
//!
//! A load starts from [`Settings::DEFAULT`]: unknown fields are skipped,
//! missing or rejected ones keep their defaults ([`FieldReport`]), and
//! settings that fail [`Settings::validate`] as a whole are refused
//! ([`StorageError::Invalid`]). Loading and saving are not on the frame
//! path (`sequential-storage` has panic paths).
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Settings in flash”).

mod error;
mod fields;
mod record;
mod report;
mod sectors;
mod seeding;
mod storage;
mod store;
mod tlv;
mod tlv_inputs;
mod v1;
mod values;

pub use error::{FlashFailed, StorageError};
pub use fields::{FIELDS, Field, SETTINGS_LEN, field};
pub use record::{DecodeError, EncodeError, RawRecord, Record};
#[cfg(feature = "postcard")]
pub use record::{decode_postcard, encode_postcard};
pub use report::{FieldReport, FieldSet, Loaded};
pub use sectors::SectorWise;
pub use sequential_storage::map::MapConfigError;
pub use storage::{RamStorage, SettingsStorage};
pub use store::{SaveError, SettingsStore, buffer_len};
pub use values::{Settings, SettingsError, SettingsSource, Validated};

/// Bytes of fields a newer firmware may have added that a store of
/// [`Settings`] still reads (skipping them): ten four-byte values.
pub const NEWER_FIELDS: usize = 60;

/// The work buffer of a store of [`Settings`] (see [`buffer_len`]): the
/// longest record, and [`NEWER_FIELDS`].
pub const SETTINGS_BUFFER: usize = buffer_len(SETTINGS_LEN + NEWER_FIELDS);
