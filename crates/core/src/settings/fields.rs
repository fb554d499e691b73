//! The fields of the [`Settings`] record: one row per field, its id, its
//! name and where its value lives (see the [module docs](super) for the
//! record's layout and how to add a field).

use crate::driver::DriverConfig;
use crate::gestures::{GestureKind, SETTINGS_IDS};

use super::record::{DecodeError, EncodeError, Record};
use super::report::{FieldReport, FieldSet};
use super::tlv::{Entries, Entry, FieldValue, HEADER, Truncated, Writer};
use super::v1;
use super::values::{Settings, SettingsError};

/// A field of the record, as the table lists it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// Its id in the record: never reused, never renumbered.
    pub id: u8,
    /// Its name (`servo.pitch.neutral`), for tools and tests.
    pub name: &'static str,
    /// Most bytes its value takes.
    pub max_len: usize,
}

/// A structure kept as tagged fields: what the record's encoder and
/// decoder need from a table of fields. The table below implements it for
/// [`Settings`]; a test implements it for a layout with one field more.
pub(super) trait Fields: Sized {
    /// The ids of the table.
    const KNOWN: FieldSet;
    /// The values a field missing from a record takes.
    const DEFAULT: Self;

    /// Writes every field.
    fn write(&self, w: &mut Writer<'_>);

    /// Reads field `id` from its bytes: `Some(true)` if it holds them now,
    /// `Some(false)` if they are not a value of its type (the field is left
    /// as it was), `None` if the table has no field `id`.
    fn read(&mut self, id: u8, bytes: &[u8]) -> Option<bool>;
}

/// Sets `place` to the value `bytes` hold; `false` (and `place` as it
/// was) if they hold none.
pub(super) fn read_into<T: FieldValue>(place: &mut T, bytes: &[u8]) -> bool {
    match T::from_bytes(bytes) {
        Some(value) => {
            *place = value;
            true
        }
        None => false,
    }
}

/// The longest value of `T` (for [`SETTINGS_LEN`], at compile time).
const fn max_len<T: FieldValue>(_: &T) -> usize {
    T::MAX_LEN
}

/// Whether no id is listed twice.
const fn unique(fields: &[Field]) -> bool {
    let mut i = 0;
    while i < fields.len() {
        let mut j = i + 1;
        while j < fields.len() {
            if fields[i].id == fields[j].id {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// The ids of every gesture's block (see [`GestureKind::row`]'s
/// `settings`): `SETTINGS_IDS` ids each.
const fn gesture_ids() -> [u8; GESTURE_FIELDS] {
    let mut ids = [0; GESTURE_FIELDS];
    let mut i = 0;
    while i < GESTURE_FIELDS {
        let kind = GestureKind::ALL[i / SETTINGS_IDS as usize];
        ids[i] = kind.row().settings + (i % SETTINGS_IDS as usize) as u8;
        i += 1;
    }
    ids
}

/// The settings fields of the gestures' defaults: [`SETTINGS_IDS`] a
/// gesture.
const GESTURE_FIELDS: usize = GestureKind::COUNT * SETTINGS_IDS as usize;

/// The gesture field `id`, as the gesture and the place in its block.
const fn gesture_field(id: u8) -> Option<(GestureKind, u8)> {
    let mut k = 0;
    while k < GestureKind::COUNT {
        let kind = GestureKind::ALL[k];
        let first = kind.row().settings;
        if id >= first && id - first < SETTINGS_IDS {
            return Some((kind, id - first));
        }
        k += 1;
    }
    None
}

/// The table: `id "name" => s.place;` per field, in the order they are
/// written, then every gesture's block. It makes [`FIELDS`],
/// [`SETTINGS_LEN`] and the [`Fields`] implementation of [`Settings`],
/// and checks that no id is used twice.
macro_rules! fields {
    ($s:ident; $($id:literal $name:literal => $place:expr;)+) => {
        /// The fields of the table's rows (the gestures' blocks follow).
        const ROWS: usize = [$($id),+].len();

        /// Every field of the [`Settings`] record, in the order a save writes
        /// them.
        pub const FIELDS: &[Field] = &{
            let $s = &Settings::DEFAULT;
            let rows = [$(Field { id: $id, name: $name, max_len: max_len(&$place) }),+];
            let d = &GestureKind::DEFAULTS[0];
            let lens = [
                max_len(&d.amplitude),
                max_len(&d.cycles),
                max_len(&d.slow),
                max_len(&d.brisk),
                max_len(&d.intensity),
            ];
            let ids = gesture_ids();
            let mut all = [rows[0]; ROWS + GESTURE_FIELDS];
            let mut i = 0;
            while i < ROWS + GESTURE_FIELDS {
                all[i] = if i < ROWS {
                    rows[i]
                } else {
                    let g = i - ROWS;
                    let names = &GestureKind::ALL[g / SETTINGS_IDS as usize].row().fields;
                    let place = g % SETTINGS_IDS as usize;
                    let name = match place {
                        0 => names.amplitude,
                        1 => names.cycles,
                        2 => names.slow,
                        3 => names.brisk,
                        _ => names.intensity,
                    };
                    Field { id: ids[g], name, max_len: lens[place] }
                };
                i += 1;
            }
            all
        };

        /// Most bytes a record of [`Settings`] takes: every field at its
        /// longest, with its header.
        pub const SETTINGS_LEN: usize = {
            let mut len = 0;
            let mut i = 0;
            while i < FIELDS.len() {
                len += HEADER + FIELDS[i].max_len;
                i += 1;
            }
            len
        };

        const _: () = assert!(unique(FIELDS), "two fields of the settings share an id");

        impl Fields for Settings {
            const KNOWN: FieldSet = FieldSet::of(&[$($id),+]).union(&FieldSet::of(&gesture_ids()));
            const DEFAULT: Self = Settings::DEFAULT;

            fn write(&self, w: &mut Writer<'_>) {
                let $s = self;
                $(w.field($id, &$place);)+
                for kind in GestureKind::ALL {
                    let first = kind.row().settings;
                    let d = $s.behaviour.defaults(kind);
                    w.field(first, &d.amplitude);
                    w.field(first + 1, &d.cycles);
                    w.field(first + 2, &d.slow);
                    w.field(first + 3, &d.brisk);
                    w.field(first + 4, &d.intensity);
                }
            }

            fn read(&mut self, id: u8, bytes: &[u8]) -> Option<bool> {
                let $s = self;
                match id {
                    $($id => Some(read_into(&mut $place, bytes)),)+
                    _ => {
                        let (kind, place) = gesture_field(id)?;
                        let d = $s.behaviour.defaults_mut(kind);
                        Some(match place {
                            0 => read_into(&mut d.amplitude, bytes),
                            1 => read_into(&mut d.cycles, bytes),
                            2 => read_into(&mut d.slow, bytes),
                            3 => read_into(&mut d.brisk, bytes),
                            _ => read_into(&mut d.intensity, bytes),
                        })
                    }
                }
            }
        }
    };
}

// Ids 1 to 56 are the fields of layout version 1, in its order (`v1.rs`).
// A new field takes the next free id (now 68), at the end; a new gesture's
// block of five takes the next five free ids. (Ids 80 and up are taken in
// blocks: 80 the DMX receiver's, 90 the servos' outputs'.)
fields! { s;
    // The servos: pulses in µs, the scale in ns per degree, the direction,
    // the angle limits in millidegrees.
    1 "servo.pitch.neutral" => s.servos[0].neutral;
    2 "servo.pitch.per_degree" => s.servos[0].per_degree;
    3 "servo.pitch.direction" => s.servos[0].direction;
    4 "servo.pitch.min" => s.servos[0].min_pulse;
    5 "servo.pitch.max" => s.servos[0].max_pulse;
    6 "servo.pitch.limit_min" => s.servos[0].limits.min;
    7 "servo.pitch.limit_max" => s.servos[0].limits.max;
    8 "servo.roll.neutral" => s.servos[1].neutral;
    9 "servo.roll.per_degree" => s.servos[1].per_degree;
    10 "servo.roll.direction" => s.servos[1].direction;
    11 "servo.roll.min" => s.servos[1].min_pulse;
    12 "servo.roll.max" => s.servos[1].max_pulse;
    13 "servo.roll.limit_min" => s.servos[1].limits.min;
    14 "servo.roll.limit_max" => s.servos[1].limits.max;
    15 "servo.yaw.neutral" => s.servos[2].neutral;
    16 "servo.yaw.per_degree" => s.servos[2].per_degree;
    17 "servo.yaw.direction" => s.servos[2].direction;
    18 "servo.yaw.min" => s.servos[2].min_pulse;
    19 "servo.yaw.max" => s.servos[2].max_pulse;
    20 "servo.yaw.limit_min" => s.servos[2].limits.min;
    21 "servo.yaw.limit_max" => s.servos[2].limits.max;
    // Ids 22 to 36: the gestures' defaults (nod, shake, tilt: their
    // `settings` blocks in the gesture table), written after these rows:
    // amplitude in millidegrees, cycles, slow and brisk frequencies in mHz,
    // intensity in percent.
    // Every gesture: highest frequency (mHz), longest gesture and blend (ms).
    37 "gesture.max_frequency" => s.behaviour.max_frequency;
    38 "gesture.longest" => s.behaviour.longest_gesture;
    39 "gesture.blend" => s.behaviour.blend;
    // Gaze moves (ms).
    40 "gaze.base" => s.behaviour.gaze.base;
    41 "gaze.per_degree" => s.behaviour.gaze.per_degree;
    42 "gaze.hold" => s.behaviour.gaze.hold;
    43 "gaze.longest" => s.behaviour.gaze.longest;
    // The idle layer.
    44 "idle.amplitude" => s.behaviour.idle.amplitude;
    45 "idle.duck" => s.behaviour.idle.duck;
    46 "idle.fade" => s.behaviour.idle.fade;
    // The gesture mode's limits per axis: °/s and °/s².
    47 "gesture_limits.pitch.speed" => s.behaviour.gesture_limits[0].max_speed;
    48 "gesture_limits.pitch.accel" => s.behaviour.gesture_limits[0].max_accel;
    49 "gesture_limits.roll.speed" => s.behaviour.gesture_limits[1].max_speed;
    50 "gesture_limits.roll.accel" => s.behaviour.gesture_limits[1].max_accel;
    51 "gesture_limits.yaw.speed" => s.behaviour.gesture_limits[2].max_speed;
    52 "gesture_limits.yaw.accel" => s.behaviour.gesture_limits[2].max_accel;
    53 "gesture.settle" => s.behaviour.settle;
    // The idle motion's seeds.
    54 "seed.pitch" => s.seeds[0];
    55 "seed.roll" => s.seeds[1];
    56 "seed.yaw" => s.seeds[2];
    // The DMX receiver (ids from 80: 57 and up are other fields').
    80 "dmx.on" => s.dmx.on;
    81 "dmx.address" => s.dmx.address;
    // Rest: the timer (s, 0 for never), the pose (m°), relax (0 or 1).
    57 "rest.after" => s.inputs.rest_after;
    58 "rest.pose.pitch" => s.behaviour.rest.pose[0];
    59 "rest.pose.roll" => s.behaviour.rest.pose[1];
    60 "rest.pose.yaw" => s.behaviour.rest.pose[2];
    61 "rest.relax" => s.behaviour.rest.relax;
    // How much a held look ducks the idle on its axes (%).
    62 "gaze.duck" => s.behaviour.gaze.duck;
    // The trigger inputs' roles, GP2 to GP5 (see `tlv_inputs.rs`).
    63 "input.2" => s.inputs.roles[0];
    64 "input.3" => s.inputs.roles[1];
    65 "input.4" => s.inputs.roles[2];
    66 "input.5" => s.inputs.roles[3];
    // The servos' PWM rate and the frame rate, Hz (a record without it
    // runs at 50 Hz).
    67 "servo.rate" => s.rate;
    // The radar and the tracking (ids from 90: 68 and up are left for
    // other fields): switches, the eyes' height (mm), the radar's bearing
    // (m°), whom first (0 nearest, 1 newest).
    90 "radar.on" => s.track.radar;
    91 "track.gaze" => s.track.gaze;
    92 "track.height" => s.track.height;
    93 "track.mount" => s.track.mount;
    94 "track.prefer" => s.track.prefer;
    // Where the idle's seeds come from (0 the board's id, 1 the paper's,
    // 2 `seed.*` as chosen). A record without it is migrated: see
    // `Settings::seeding_of_older`.
    95 "seed.mode" => s.seeding;
}

/// The id of the seeds' source, which records of older firmware lack.
const SEED_MODE: u8 = 95;

/// The field `id` of the table, if there is one.
#[must_use]
pub fn field(id: u8) -> Option<&'static Field> {
    FIELDS.iter().find(|f| f.id == id)
}

/// Writes every field of `record` (the record's bytes).
pub(super) fn encode_fields<T: Fields>(record: &T, buf: &mut [u8]) -> Result<usize, EncodeError> {
    let mut w = Writer::new(buf);
    record.write(&mut w);
    w.finish()
}

/// A record of `T` from its entries, `(id, value)` in stored order: every
/// field found takes its stored value, the rest keep their defaults, and
/// `report` says which fields were unknown, missing or rejected.
///
/// # Errors
/// [`DecodeError::Malformed`] for an entry cut short, or a field twice.
pub(super) fn decode_fields<'a, T: Fields, I>(
    entries: impl Iterator<Item = Entry<'a>>,
    report: &mut FieldReport,
) -> Result<T, DecodeError<I>> {
    let mut record = T::DEFAULT;
    let mut seen = FieldSet::EMPTY;
    for entry in entries {
        let (id, bytes) = entry.map_err(|Truncated| DecodeError::Malformed)?;
        if !seen.insert(id) {
            return Err(DecodeError::Malformed);
        }
        match record.read(id, bytes) {
            Some(true) => {}
            Some(false) => _ = report.rejected.insert(id),
            None => _ = report.unknown.insert(id),
        }
    }
    report.missing = T::KNOWN.without(&seen);
    Ok(record)
}

impl Record for Settings {
    /// Version 2: tagged fields. Version 1 (fixed layout) is migrated.
    const VERSION: u16 = 2;
    type Invalid = SettingsError;

    fn encode(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        encode_fields(self, buf)
    }

    /// Reads version 2, or migrates version 1; then validates the settings
    /// with the built-in driver configuration ([`DriverConfig::DEFAULT`]).
    fn decode(
        version: u16,
        bytes: &[u8],
        report: &mut FieldReport,
    ) -> Result<Self, DecodeError<SettingsError>> {
        let mut settings: Self = match version {
            1 => decode_fields(v1::entries(bytes)?, report)?,
            2 => decode_fields(Entries::new(bytes), report)?,
            _ => return Err(DecodeError::Version),
        };
        if report.missing.contains(SEED_MODE) {
            settings.seeding = Self::seeding_of_older(settings.seeds);
        }
        match settings.validate(&DriverConfig::DEFAULT) {
            Ok(_) => Ok(settings),
            Err(e) => Err(DecodeError::Invalid(e)),
        }
    }
}

#[cfg(test)]
mod tests;
