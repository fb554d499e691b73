//! Settings kept in flash: one record of tagged fields, written so that a
//! power cut at any moment leaves the old record or the new one, never a
//! mix, and read so that a firmware update keeps them.
//!
//! - [`Record`]: how a settings type turns into bytes and back, with the
//!   version of that layout. With the `postcard` feature,
//!   [`encode_postcard`] and [`decode_postcard`] do it for any serde type.
//! - [`Settings`]: the head's settings (servos, behaviour, seeds), one
//!   validated record ([`Settings::DEFAULT`]: the built-in configuration),
//!   its fields listed in [`FIELDS`].
//! - [`SettingsStorage`]: what the console's `save` and `load` call, a
//!   trait each board implements; [`RamStorage`] keeps the record in RAM.
//! - [`SettingsStore`]: the record in a range of NOR flash (anything that
//!   implements `embedded_storage_async::nor_flash::NorFlash`, such as
//!   embassy-rp's flash driver), kept by `sequential-storage`'s map. A
//!   load gives the record with a [`FieldReport`] ([`Loaded`]).
//!
//! # The record
//!
//! The flash holds one item (map key 0). Its value is the layout version
//! (a little-endian `u16`, now **2**), then the fields, each as
//!
//! | id | length | value |
//! |---|---|---|
//! | 1 byte | 1 byte | `length` bytes |
//!
//! in the order of the table in `fields.rs`, which gives each field its
//! id, a name and its place in [`Settings`] (at most [`SETTINGS_LEN`]
//! bytes in all). A value is written by its type:
//! a count of µs, ms, ns per degree, mHz, °/s or °/s², and a seed, as four
//! little-endian bytes; an angle as four (millidegrees, two's
//! complement); a percentage (0 to 100), a direction (0 normal, 1
//! reversed), a switch (0 off, 1 on) or a gesture's cycles as one byte; a
//! DMX address (1 to 503) as two little-endian bytes; a gaze hold as five
//! (0 and the ms of the return, or 1 and four zero bytes for `stay`); the
//! rest timer as four (seconds, 0 for `never`); a trigger input's role and
//! a button's action as `tlv_inputs.rs` says (20 bytes at most).
//!
//! # Loading: fields added, fields unknown, values out of range
//!
//! A load starts from [`Settings::DEFAULT`] and takes each field it finds:
//!
//! - a field this firmware knows takes its stored value;
//! - a field it does not know (saved by a newer firmware) is skipped, by
//!   its length: [`FieldReport::unknown`];
//! - a field it knows that the record lacks (saved by an older firmware,
//!   before the field was added) keeps its default:
//!   [`FieldReport::missing`];
//! - a field whose bytes are not a value of its type (a wrong length, a
//!   percentage over 100, a direction 2) keeps its default:
//!   [`FieldReport::rejected`], a warning in the boot log;
//! - an entry that runs past the end of the record, or a field stored
//!   twice, makes the whole record [`StorageError::Corrupt`].
//!
//! Then the settings as a whole are checked as [`Settings::validate`]
//! checks them, with the built-in driver configuration. If they fail, the
//! **whole record is refused** with the reason
//! ([`StorageError::Invalid`]`(`[`SettingsError`]`)`) and the board keeps
//! its built-in settings: a calibration that is valid field by field but
//! not as a whole (a neutral pulse outside the pulse range) has no single
//! field to blame, and guessing one could point a servo past its stop.
//!
//! # Versions and migrations
//!
//! Adding a field does not change the version: a newer firmware reads the
//! record of an older one (the new field on its default), and an older
//! firmware reads a newer one's (the new field skipped; its next `save`
//! leaves it out). The version changes only if the layout of the entries
//! itself changes, and then the new firmware keeps a migration from the
//! old one, as it does for version 1 (`v1.rs`: the 56 fields' values one
//! after the other, without ids and lengths, read as the same fields). A
//! record of a version with no migration is [`StorageError::Older`], of a
//! version above this firmware's [`StorageError::Newer`]: the board keeps
//! its built-in settings, with a warning.
//!
//! # Adding a field
//!
//! 1. Add it where it belongs in [`Settings`] (or the configuration it is
//!    part of), with its default in [`Settings::DEFAULT`] and its check in
//!    [`Settings::validate`]; its default must be valid with any settings
//!    an older firmware saved.
//! 2. Add one row to the table in `fields.rs`, with the next free id (the
//!    comment above the table says which):
//!    `68 "look.speed" => s.behaviour.gaze.speed;`.
//! 3. Only if its type is new to the record: implement `FieldValue` for it
//!    in `tlv.rs` (its bytes, and which bytes are a value).
//!
//! Nothing else: no version, no migration. Never reuse or renumber an id
//! and never change how a field's value is written: a field whose meaning
//! or encoding changes gets a new id (the old row is deleted, and its id
//! is left unused). A duplicate id does not compile.
//!
//! # Buffer
//!
//! The store reads the whole item into its work buffer,
//! [`SETTINGS_BUFFER`]: the longest record ([`SETTINGS_LEN`]), the map's
//! key and the version, plus [`NEWER_FIELDS`] bytes for fields a newer
//! firmware may have added (a newer record that is longer still is
//! [`StorageError::TooLong`]; the built-in settings are used, and the next
//! `save` starts the store afresh). Each field added makes the buffer
//! grow by its value's length plus two bytes.
//!
//! # Power cuts
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
//! [`StorageError::Empty`] if none is left; damage the map cannot repair is
//! [`StorageError::Corrupt`]. A load never returns bytes that were not saved
//! as a record. A save reads its record back and writes it again past a
//! damaged spot if needed.
//!
//! `sequential-storage` indexes and unwraps internally, so loading and
//! saving are not free of panic paths; they run at boot and on `save` or
//! `load`, never on the frame path.

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
