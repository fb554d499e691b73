//! The settings table's record: round trips, versions, migration, and a
//! firmware with one field more.
use super::*;
use crate::command::Percent;
use crate::settings::{Loaded, RamStorage, SettingsStorage, StorageError, record::open_record};
use crate::units::{Microseconds, Millis};

/// An id the table will not reach for a long time: the field a test
/// firmware adds.
const NEW: u8 = 255;

/// The settings of a firmware with one field more than this one (the
/// real table and one row), as the next firmware will be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Grown {
    settings: Settings,
    rest: Millis,
}

impl Fields for Grown {
    const KNOWN: FieldSet = <Settings as Fields>::KNOWN.with(NEW);
    const DEFAULT: Self = Self {
        settings: Settings::DEFAULT,
        rest: Millis(30_000),
    };

    fn write(&self, w: &mut Writer<'_>) {
        self.settings.write(w);
        w.field(NEW, &self.rest);
    }

    fn read(&mut self, id: u8, bytes: &[u8]) -> Option<bool> {
        match id {
            NEW => Some(read_into(&mut self.rest, bytes)),
            _ => self.settings.read(id, bytes),
        }
    }
}

impl Record for Grown {
    const VERSION: u16 = Settings::VERSION;
    type Invalid = SettingsError;

    fn encode(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        encode_fields(self, buf)
    }

    fn decode(
        version: u16,
        bytes: &[u8],
        report: &mut FieldReport,
    ) -> Result<Self, DecodeError<SettingsError>> {
        let grown: Self = match version {
            2 => decode_fields(Entries::new(bytes), report)?,
            _ => return Err(DecodeError::Version),
        };
        match grown.settings.validate(&DriverConfig::DEFAULT) {
            Ok(_) => Ok(grown),
            Err(e) => Err(DecodeError::Invalid(e)),
        }
    }
}

/// Settings that differ from the built-in ones in many fields.
fn calibrated() -> Settings {
    let mut s = Settings::DEFAULT;
    s.servos[0].neutral = Microseconds(1520);
    s.servos[2].per_degree = crate::servo::NanosPerDegree(10_500);
    s.servos[1].direction = crate::servo::Direction::Reversed;
    s.behaviour.idle.amplitude = Percent::new(70).unwrap();
    s.behaviour.gaze.hold = crate::command::Hold::Stay;
    s.seeds = [1, 2, 3];
    // Seeds a person chose (a record of an older firmware that holds them
    // loads so).
    s.seeding = crate::seed::Seeding::Chosen;
    s.validate(&DriverConfig::DEFAULT).unwrap();
    s
}

/// `record` as a store keeps it: the version, then the fields.
fn stored<R: Record>(record: &R) -> Vec<u8> {
    let mut buf = [0; 1024];
    let n = record.encode(&mut buf[2..]).unwrap();
    buf[..2].copy_from_slice(&R::VERSION.to_le_bytes());
    buf[..2 + n].to_vec()
}

fn open<R: Record>(stored: &[u8]) -> Result<Loaded<R>, StorageError<(), R::Invalid>> {
    open_record::<R, ()>(stored)
}

#[test]
fn the_table_names_each_field_once() {
    let mut names: Vec<_> = FIELDS.iter().map(|f| f.name).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), FIELDS.len());
    assert_eq!(
        SETTINGS_LEN,
        FIELDS.iter().map(|f| HEADER + f.max_len).sum::<usize>()
    );
    assert_eq!(FIELDS.len(), <Settings as Fields>::KNOWN.len());
    assert_eq!(field(1).map(|f| f.name), Some("servo.pitch.neutral"));
    assert!(
        !<Settings as Fields>::KNOWN.contains(NEW),
        "the test's id is taken"
    );
    // Every field is written, once, in the table's order.
    let bytes = stored(&Settings::DEFAULT);
    let ids: Vec<u8> = Entries::new(&bytes[2..]).map(|e| e.unwrap().0).collect();
    assert_eq!(ids, FIELDS.iter().map(|f| f.id).collect::<Vec<_>>());
    assert!(bytes.len() - 2 <= SETTINGS_LEN);
}

/// The next firmware adds a field: a record saved today loads there,
/// every field as saved, the new one on its default.
#[test]
fn a_record_of_today_loads_after_a_field_is_added() {
    let today = calibrated();
    let loaded = open::<Grown>(&stored(&today)).unwrap();
    assert_eq!(loaded.record.settings, today);
    assert_eq!(loaded.record.rest, Grown::DEFAULT.rest);
    assert_eq!(loaded.version, 2);
    assert_eq!(
        loaded.fields,
        FieldReport {
            missing: FieldSet::of(&[NEW]),
            ..FieldReport::default()
        }
    );
    // Through the console's storage, as the board saves it.
    let mut ram = RamStorage::<512>::new();
    ram.save(&today).unwrap();
    assert_eq!(open::<Grown>(ram.raw()).unwrap().record.settings, today);
    // And the new firmware's own record round-trips.
    let grown = Grown {
        settings: today,
        rest: Millis(5_000),
    };
    let back = open::<Grown>(&stored(&grown)).unwrap();
    assert_eq!(back.record, grown);
    assert!(back.fields.is_clean());
}

/// A record of that next firmware loads today: its new field skipped
/// and reported, every other field as saved.
#[test]
fn a_field_of_a_newer_firmware_is_skipped_and_reported() {
    let grown = Grown {
        settings: calibrated(),
        rest: Millis(5_000),
    };
    let loaded = open::<Settings>(&stored(&grown)).unwrap();
    assert_eq!(loaded.record, grown.settings);
    assert_eq!(
        loaded.fields,
        FieldReport {
            unknown: FieldSet::of(&[NEW]),
            ..FieldReport::default()
        }
    );
    let mut ram = RamStorage::<512>::new();
    ram.set_raw(&stored(&grown)).unwrap();
    assert_eq!(ram.load(), Ok(grown.settings));
}

/// The entries of `stored`'s record, edited, as a store keeps them.
fn edited(stored: &[u8], edit: impl Fn(u8, &[u8]) -> Option<Vec<u8>>) -> Vec<u8> {
    let mut out = stored[..2].to_vec();
    for entry in Entries::new(&stored[2..]) {
        let (id, value) = entry.unwrap();
        if let Some(value) = edit(id, value) {
            out.push(id);
            out.push(u8::try_from(value.len()).unwrap());
            out.extend(value);
        }
    }
    out
}

#[test]
fn a_value_out_of_its_range_takes_its_default_and_is_reported() {
    let today = calibrated();
    // idle.amplitude 170 %, servo.roll.direction 2, a seed of 3 bytes.
    let bytes = edited(&stored(&today), |id, v| match id {
        44 => Some(vec![170]),
        10 => Some(vec![2]),
        55 => Some(v[..3].to_vec()),
        _ => Some(v.to_vec()),
    });
    let loaded = open::<Settings>(&bytes).unwrap();
    assert_eq!(loaded.fields.rejected, FieldSet::of(&[10, 44, 55]));
    let mut expected = today;
    expected.behaviour.idle.amplitude = Settings::DEFAULT.behaviour.idle.amplitude;
    expected.servos[1].direction = Settings::DEFAULT.servos[1].direction;
    expected.seeds[1] = Settings::DEFAULT.seeds[1];
    assert_eq!(loaded.record, expected);
}

#[test]
fn settings_that_fail_as_a_whole_are_refused_with_the_reason() {
    let mut bad = calibrated();
    bad.servos[2].neutral = Microseconds(2600);
    let err = open::<Settings>(&stored(&bad)).unwrap_err();
    let Err(why) = bad.validate(&DriverConfig::DEFAULT) else {
        panic!("valid")
    };
    assert_eq!(err, StorageError::Invalid(why));
    // A missing field whose default does not fit the others: refused too.
    let mut narrow = Settings::DEFAULT;
    narrow.servos[0].min_pulse = Microseconds(1600);
    narrow.servos[0].neutral = Microseconds(1700);
    narrow.servos[0].limits.min = crate::units::Angle::ZERO;
    narrow.validate(&DriverConfig::DEFAULT).unwrap();
    let without_neutral = edited(&stored(&narrow), |id, v| (id != 1).then(|| v.to_vec()));
    assert!(matches!(
        open::<Settings>(&without_neutral),
        Err(StorageError::Invalid(SettingsError::Driver(_)))
    ));
}

#[test]
fn a_cut_entry_or_a_field_twice_is_corrupt() {
    let bytes = stored(&calibrated());
    for cut in 2..bytes.len() {
        let loaded = open::<Settings>(&bytes[..cut]);
        // A cut between two entries leaves fields missing, which
        // validation may accept (the built-in values fit).
        let between = Entries::new(&bytes[2..cut]).all(|e| e.is_ok());
        match loaded {
            Err(StorageError::Corrupt) => assert!(!between, "cut at {cut}"),
            Ok(l) => assert!(between && !l.fields.missing.is_empty(), "cut at {cut}"),
            Err(StorageError::Invalid(_)) => assert!(between, "cut at {cut}"),
            Err(e) => panic!("cut at {cut}: {e:?}"),
        }
    }
    let mut twice = bytes.clone();
    twice.extend([1, 4, 0xdc, 5, 0, 0]);
    assert_eq!(open::<Settings>(&twice), Err(StorageError::Corrupt));
    let mut unknown_twice = bytes;
    unknown_twice.extend([NEW, 0, NEW, 1, 7]);
    assert_eq!(open::<Settings>(&unknown_twice), Err(StorageError::Corrupt));
    assert_eq!(open::<Settings>(&[2]), Err(StorageError::Corrupt));
}

#[test]
fn versions() {
    let bytes = stored(&calibrated());
    let with = |v: u16| {
        let mut b = bytes.clone();
        b[..2].copy_from_slice(&v.to_le_bytes());
        b
    };
    assert_eq!(
        open::<Settings>(&with(3)),
        Err(StorageError::Newer { found: 3 })
    );
    assert_eq!(
        open::<Settings>(&with(0)),
        Err(StorageError::Older { found: 0 })
    );
    // Version 2's bytes are not a version 1 record.
    assert_eq!(open::<Settings>(&with(1)), Err(StorageError::Corrupt));
    // An empty record of version 2: every field on its default.
    let empty = open::<Settings>(&2_u16.to_le_bytes()).unwrap();
    assert_eq!(empty.record, Settings::DEFAULT);
    assert_eq!(empty.fields.missing, <Settings as Fields>::KNOWN);
}

/// Version 1 was today's values without ids and lengths, in the order
/// of their ids: stripping the headers of a record of today gives the
/// record version 1 wrote.
#[test]
fn version_1_is_migrated_field_by_field() {
    for settings in [Settings::DEFAULT, calibrated()] {
        let today = stored(&settings);
        let mut fields: Vec<(u8, &[u8])> = Entries::new(&today[2..]).map(Result::unwrap).collect();
        fields.sort_by_key(|&(id, _)| id);
        let mut v1 = 1_u16.to_le_bytes().to_vec();
        for (id, value) in fields {
            if id <= 56 {
                v1.extend(value);
            }
        }
        assert_eq!(v1.len(), 2 + v1::V1_LEN);
        let loaded = open::<Settings>(&v1).unwrap();
        assert_eq!(loaded.record, settings);
        assert_eq!(loaded.version, 1);
        assert_eq!(
            loaded.fields.missing,
            <Settings as Fields>::KNOWN.without(&FieldSet::of(&[
                1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23,
                24, 25, 26, 27, 28, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44,
                45, 46, 47, 48, 49, 50, 51, 52, 53, 54, 55, 56
            ]))
        );
        // A version 1 record of another length is not one.
        for n in [0, 1, v1.len() - 1] {
            assert_eq!(
                open::<Settings>(&v1[..n.max(2)]),
                Err(StorageError::Corrupt)
            );
        }
        let mut long = v1.clone();
        long.push(0);
        assert_eq!(open::<Settings>(&long), Err(StorageError::Corrupt));
    }
}
