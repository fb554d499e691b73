//! The firmware's settings record: every field round-trips, every field's
//! validation error is typed, a record of layout version 1 (the fixture
//! in `fixtures/`) loads intact, and damaged or newer records are refused
//! with a typed error (never a panic, never settings that were not saved).

use futures::executor::block_on;
use idle_head_core::behaviour::{BehaviourError, MilliHertz};
use idle_head_core::command::{GestureKind, Hold, InputRole, Percent, RestAfter};
use idle_head_core::driver::{
    ConfigError, DegreesPerSecond, DegreesPerSecondSquared, DriverConfig,
};
use idle_head_core::servo::{NanosPerDegree, ServoError, ServoRate};
use idle_head_core::settings::{
    DecodeError, FIELDS, FieldReport, FieldSet, Loaded, RamStorage, Record, SETTINGS_BUFFER,
    SETTINGS_LEN, Settings, SettingsError, SettingsStorage, SettingsStore, StorageError, field,
};
use idle_head_core::{Angle, AngleRange, Axis, Direction, Microseconds, Millis};
use proptest::prelude::RngExt as _;
use sequential_storage::mock_flash::{MockFlashBase, WriteCountCheck};

mod v1;

use v1::{V1_RECORD, fixture_v1};

/// A change to the built-in settings.
type Edit = fn(&mut Settings);

fn encode(s: &Settings) -> Vec<u8> {
    let mut buf = [0; 512];
    let n = s.encode(&mut buf).unwrap();
    buf[..n].to_vec()
}

/// A record of today's layout, and what the load reported.
fn decode(bytes: &[u8]) -> Result<(Settings, FieldReport), DecodeError<SettingsError>> {
    let mut report = FieldReport::default();
    Settings::decode(Settings::VERSION, bytes, &mut report).map(|s| (s, report))
}

#[test]
fn defaults_are_the_built_in_configuration_and_round_trip() {
    assert_eq!(Settings::DEFAULT.servos, DriverConfig::DEFAULT.servos);
    assert_eq!(Settings::DEFAULT.seeds, [127, 259, 8821]);
    let bytes = encode(&Settings::DEFAULT);
    // Every field at its longest but the inputs' roles: off, one byte each
    // of their twenty.
    assert_eq!(bytes.len(), SETTINGS_LEN - 4 * 19);
    assert_eq!(
        decode(&bytes),
        Ok((Settings::DEFAULT, FieldReport::default()))
    );
    // A buffer one byte short is refused, not overrun.
    let mut short = vec![0; bytes.len() - 1];
    assert!(Settings::DEFAULT.encode(&mut short).is_err());
}

#[test]
fn every_field_round_trips() {
    let mut rng = host_tests::console::rng(11);
    let mut checked = 0;
    for _ in 0..20_000 {
        let mut s = Settings::DEFAULT;
        for c in &mut s.servos {
            c.neutral = Microseconds(rng.random_range(1400..=1600));
            c.per_degree = NanosPerDegree(rng.random_range(9_000..=13_000));
            c.min_pulse = Microseconds(rng.random_range(500..=1000));
            c.max_pulse = Microseconds(rng.random_range(2000..=2500));
            c.direction = if rng.random_bool(0.5) {
                Direction::Reversed
            } else {
                Direction::Normal
            };
        }
        s.behaviour.idle.amplitude = Percent::new(rng.random_range(0..=100)).unwrap();
        s.behaviour.idle.duck = Percent::new(rng.random_range(0..=100)).unwrap();
        s.behaviour.gaze.hold = if rng.random_bool(0.3) {
            Hold::Stay
        } else {
            Hold::Return(Millis(rng.random_range(0..=3_600_000)))
        };
        s.behaviour.gaze.base = Millis(rng.random_range(0..=5000));
        s.behaviour.defaults_mut(GestureKind::Shake).intensity =
            Percent::new(rng.random_range(0..=100)).unwrap();
        s.behaviour.settle = Millis(rng.random_range(0..=5000));
        s.seeds = [rng.random(), rng.random(), rng.random()];
        s.behaviour.rest.pose = [0; 3].map(|_| Angle::from_millidegrees(rng.random()));
        s.behaviour.rest.relax = rng.random_bool(0.5);
        s.behaviour.gaze.duck = Percent::new(rng.random_range(0..=100)).unwrap();
        s.rate = ServoRate::new(rng.random_range(50..=333)).unwrap();
        s.inputs.rest_after = if rng.random_bool(0.2) {
            RestAfter::Never
        } else {
            RestAfter::Seconds(rng.random_range(1..=86_400))
        };
        for role in &mut s.inputs.roles {
            *role = match rng.random_range(0..3) {
                0 => InputRole::Off,
                // Any motion command a line can give.
                1 => InputRole::Button(host_tests::console::random_action(&mut rng)),
                _ => InputRole::Presence {
                    toward: rng
                        .random_bool(0.7)
                        .then(|| Angle::from_millidegrees(rng.random())),
                },
            };
        }
        if s.validate(&DriverConfig::DEFAULT).is_err() {
            continue;
        }
        let bytes = encode(&s);
        assert!(bytes.len() <= SETTINGS_LEN);
        assert_eq!(decode(&bytes), Ok((s, FieldReport::default())));
        checked += 1;
    }
    println!("settings round trips: {checked}");
    assert!(checked > 10_000);
}

/// One field changed to a value the firmware refuses, and the typed
/// error naming it.
#[test]
fn every_field_has_its_validation_error() {
    let base = DriverConfig::DEFAULT;
    let driver = |edit: fn(&mut Settings)| {
        let mut s = Settings::DEFAULT;
        edit(&mut s);
        let err = s.validate(&base).unwrap_err();
        // And a record of it does not load, for the same reason.
        assert_eq!(decode(&encode(&s)), Err(DecodeError::Invalid(err)));
        err
    };
    for axis in Axis::ALL {
        let i = axis.index();
        let servo = |e: SettingsError| match e {
            SettingsError::Driver(ConfigError::Servo { axis: a, error }) => {
                assert_eq!(a, axis);
                error
            }
            other => panic!("{axis:?}: {other:?}"),
        };
        let mut s = Settings::DEFAULT;
        s.servos[i].neutral = Microseconds(3000);
        let e = s.validate(&base).unwrap_err();
        assert!(
            matches!(servo(e), ServoError::NeutralOutsidePulseRange { .. }),
            "{e}"
        );
        let mut s = Settings::DEFAULT;
        s.servos[i].per_degree = NanosPerDegree(0);
        assert!(s.validate(&base).is_err());
        let mut s = Settings::DEFAULT;
        s.servos[i].min_pulse = Microseconds(2100);
        assert!(matches!(
            servo(s.validate(&base).unwrap_err()),
            ServoError::PulseRangeEmpty { .. }
        ));
        // Past the hard bounds no setting may pass.
        for (min, max) in [(400, 2000), (1000, 2600)] {
            let mut s = Settings::DEFAULT;
            s.servos[i].min_pulse = Microseconds(min);
            s.servos[i].max_pulse = Microseconds(max);
            assert!(matches!(
                servo(s.validate(&base).unwrap_err()),
                ServoError::PulseOutsideBounds { .. }
            ));
        }
        let mut s = Settings::DEFAULT;
        s.servos[i].max_pulse = Microseconds(30_000);
        assert!(s.validate(&base).is_err());
        let mut s = Settings::DEFAULT;
        s.servos[i].limits = AngleRange::degrees(5, 10);
        assert!(s.validate(&base).is_err(), "limits excluding neutral");
        let mut s = Settings::DEFAULT;
        s.servos[i].limits = AngleRange {
            min: Angle::from_millidegrees(-400_000),
            max: Angle::ZERO,
        };
        assert!(s.validate(&base).is_err(), "limits beyond 360°");
    }
    // Behaviour: each group.
    let behaviour = |e: SettingsError| match e {
        SettingsError::Behaviour(b) => b,
        other => panic!("{other:?}"),
    };
    let cases: [(&str, Edit); 12] = [
        ("nod.amplitude", |s| {
            s.behaviour.defaults_mut(GestureKind::Nod).amplitude = Angle::from_degrees(80)
        }),
        ("shake.cycles", |s| {
            s.behaviour.defaults_mut(GestureKind::Shake).cycles = 0
        }),
        ("tilt.slow", |s| {
            s.behaviour.defaults_mut(GestureKind::Tilt).slow = MilliHertz(0)
        }),
        ("nod.brisk", |s| {
            s.behaviour.defaults_mut(GestureKind::Nod).brisk = MilliHertz(90_000)
        }),
        ("max_frequency", |s| {
            s.behaviour.max_frequency = MilliHertz(1)
        }),
        ("longest_gesture", |s| {
            s.behaviour.longest_gesture = Millis(1)
        }),
        ("blend", |s| s.behaviour.blend = Millis(1)),
        ("gaze.base", |s| s.behaviour.gaze.base = Millis(9000)),
        ("gaze.hold", |s| {
            s.behaviour.gaze.hold = Hold::Return(Millis(u32::MAX))
        }),
        ("idle.fade", |s| s.behaviour.idle.fade = Millis(0)),
        ("gesture_limits[roll].max_speed", |s| {
            s.behaviour.gesture_limits[1].max_speed = DegreesPerSecond(1);
        }),
        ("settle", |s| s.behaviour.settle = Millis(99_999)),
    ];
    for (name, edit) in cases {
        let e = behaviour(driver(edit));
        let text = e.to_string();
        if let BehaviourError::Config { field, .. } = e {
            assert_eq!(field, name, "{text}");
        } else {
            // A gesture default: the message names the gesture.
            assert!(
                text.contains(name.split('.').next().unwrap()),
                "{name}: {text}"
            );
        }
    }
    // Narrow limits make the default gestures impossible: a behaviour
    // error, not a driver one.
    let mut s = Settings::DEFAULT;
    s.servos[0].limits = AngleRange::degrees(-1, 1);
    assert!(matches!(
        s.validate(&base),
        Err(SettingsError::Behaviour(_))
    ));
}

#[test]
fn damaged_older_and_newer_records_are_typed_errors() {
    let bytes = encode(&Settings::DEFAULT);
    // Every truncation: cut inside an entry, the record is malformed; cut
    // between two, the fields after the cut are missing (on their
    // defaults, which are the values saved here).
    let mut malformed = 0;
    for n in 0..bytes.len() {
        match decode(&bytes[..n]) {
            Err(DecodeError::Malformed) => malformed += 1,
            Ok((s, report)) => {
                assert_eq!(s, Settings::DEFAULT, "{n}");
                assert!(!report.missing.is_empty(), "{n}");
            }
            other => panic!("cut at {n}: {other:?}"),
        }
    }
    assert_eq!(malformed, bytes.len() - FIELDS.len());
    // Bad values: the direction and the hold tag take their defaults.
    let mut bad = bytes.clone();
    assert_eq!(bad[12..15], [3, 1, 0], "pitch's direction");
    bad[14] = 2;
    let (s, report) = decode(&bad).unwrap();
    assert_eq!(s, Settings::DEFAULT);
    assert_eq!(report.rejected.iter().collect::<Vec<_>>(), [3]);
    // Every single-byte change: refused or a valid record, never a panic.
    let mut rng = host_tests::console::rng(12);
    let (mut refused, mut other) = (0, 0);
    for _ in 0..50_000 {
        let mut b = bytes.clone();
        let at = rng.random_range(0..b.len());
        b[at] = rng.random();
        match decode(&b) {
            Ok((s, _)) => {
                assert!(s.validate(&DriverConfig::DEFAULT).is_ok());
                other += 1;
            }
            Err(_) => refused += 1,
        }
    }
    println!("damaged records: {refused} refused, {other} still valid settings");
    assert!(refused > 0);

    // Through a store: versions are checked before the bytes.
    let mut ram = RamStorage::<{ SETTINGS_BUFFER }>::new();
    assert_eq!(ram.load(), Err(StorageError::Empty));
    ram.save(&Settings::DEFAULT).unwrap();
    assert_eq!(ram.load(), Ok(Settings::DEFAULT));
    let mut raw = ram.raw().to_vec();
    raw[..2].copy_from_slice(&0_u16.to_le_bytes());
    ram.set_raw(&raw).unwrap();
    assert_eq!(ram.load(), Err(StorageError::Older { found: 0 }));
    raw[..2].copy_from_slice(&7_u16.to_le_bytes());
    ram.set_raw(&raw).unwrap();
    assert_eq!(ram.load(), Err(StorageError::Newer { found: 7 }));
    raw[..2].copy_from_slice(&Settings::VERSION.to_le_bytes());
    raw.truncate(raw.len() - 1);
    ram.set_raw(&raw).unwrap();
    assert_eq!(ram.load(), Err(StorageError::Corrupt));
    let mut invalid = Settings::DEFAULT;
    invalid.servos[2].neutral = Microseconds(100);
    let mut rec = Settings::VERSION.to_le_bytes().to_vec();
    rec.extend(encode(&invalid));
    ram.set_raw(&rec).unwrap();
    let why = invalid.validate(&DriverConfig::DEFAULT).unwrap_err();
    assert_eq!(ram.load(), Err(StorageError::Invalid(why)));
    assert_eq!(
        StorageError::Invalid(why).to_string(),
        format!("stored settings fail validation: {why}")
    );
    // A store too small refuses the save and keeps what it holds.
    let mut tiny = RamStorage::<64>::new();
    assert_eq!(
        tiny.save(&Settings::DEFAULT),
        Err(StorageError::TooLong { needs: None })
    );
    assert_eq!(tiny.load(), Err(StorageError::Empty));
    let mut short = RamStorage::<{ SETTINGS_LEN + 1 }>::new();
    short.set_raw(V1_RECORD).unwrap();
    assert_eq!(
        short.save(&Settings::DEFAULT),
        Err(StorageError::TooLong { needs: None })
    );
    assert_eq!(short.load(), Ok(fixture_v1()));
}

/// The entries of a record of today's layout, `(id, value)`.
fn entries(mut bytes: &[u8]) -> Vec<(u8, Vec<u8>)> {
    let mut out = Vec::new();
    while let [id, len, rest @ ..] = bytes {
        let (value, rest) = rest.split_at(usize::from(*len));
        out.push((*id, value.to_vec()));
        bytes = rest;
    }
    out
}

/// `entries` as a stored record of today's version.
fn stored(entries: &[(u8, Vec<u8>)]) -> Vec<u8> {
    let mut out = Settings::VERSION.to_le_bytes().to_vec();
    for (id, value) in entries {
        out.push(*id);
        out.push(u8::try_from(value.len()).unwrap());
        out.extend(value);
    }
    out
}

/// `stored` as a board's storage loads it, and what the load reported.
fn load_stored(stored: &[u8]) -> (Result<Settings, StorageError>, FieldReport) {
    let mut ram = RamStorage::<{ SETTINGS_BUFFER }>::new();
    ram.set_raw(stored).unwrap();
    let mut report = FieldReport::default();
    let decoded = Settings::decode(Settings::VERSION, &stored[2..], &mut report);
    let loaded = ram.load();
    assert_eq!(
        loaded.ok(),
        decoded.ok(),
        "the storage and the record agree"
    );
    (ram.load(), report)
}

/// A record saved by a firmware that had one field less (each field in
/// turn) loads: every field it holds as saved, the one it lacks on its
/// default, and the load says which.
#[test]
fn a_record_without_a_field_loads_with_every_other_value() {
    let saved = fixture_v1();
    let fields = entries(&encode(&saved));
    let defaults = entries(&encode(&Settings::DEFAULT));
    for (i, (id, _)) in fields.iter().enumerate() {
        let older: Vec<_> = fields.iter().filter(|(f, _)| f != id).cloned().collect();
        let (loaded, report) = load_stored(&stored(&older));
        assert_eq!(report.missing.iter().collect::<Vec<_>>(), [*id]);
        assert!(report.unknown.is_empty() && report.rejected.is_empty());
        // Every field's default fits these saved settings, as a new field's
        // default must fit any settings an older firmware saved.
        let settings = loaded.unwrap_or_else(|e| panic!("without {id}: {e}"));
        // The saved record with field `id` taken from the defaults.
        let mut expected = fields.clone();
        expected[i] = defaults[i].clone();
        if *id == SEED_MODE {
            // The one field migrated rather than defaulted: these seeds
            // were chosen (see the test below).
            expected[i] = (SEED_MODE, vec![2]);
        }
        assert_eq!(entries(&encode(&settings)), expected, "without {id}");
    }
}

/// The id of the seeds' source (`seed.mode`).
const SEED_MODE: u8 = 95;

/// A record saved before seeds had a source: the paper's seeds (what
/// every board had unless a person chose) become the board's own, so
/// that an upgraded crowd of heads stops moving in step; seeds a person
/// chose (`seed <n>`) are kept.
#[test]
fn an_older_record_keeps_chosen_seeds_and_moves_the_papers_to_the_board() {
    use idle_head_core::seed::{BoardId, PAPER, Seeding};
    let chosen = fixture_v1();
    let without = |s: &Settings| {
        let older: Vec<_> = entries(&encode(s))
            .into_iter()
            .filter(|(id, _)| *id != SEED_MODE)
            .collect();
        load_stored(&stored(&older)).0.unwrap()
    };
    let loaded = without(&chosen);
    assert_eq!(loaded.seeding, Seeding::Chosen);
    assert_eq!(loaded.idle_seeds(BoardId(99)), chosen.seeds);
    let mut paper = chosen;
    paper.seeds = PAPER;
    let loaded = without(&paper);
    assert_eq!(loaded.seeding, Seeding::Board);
    assert_ne!(loaded.idle_seeds(BoardId(99)), PAPER);
    assert_eq!(loaded.idle_seeds(BoardId::NONE), PAPER);
    // The version 1 fixture (seeds 42, …) loads with its seeds chosen.
    assert_eq!(fixture_v1().seeding, Seeding::Chosen);
}

/// The servos' rate (field 67, two bytes of Hz): a record saved before it
/// existed boots at 50 Hz; one with a rate outside 50..=333 Hz loads at
/// 50 Hz too, the field reported as rejected; a rate saved loads as saved.
#[test]
fn the_rate_loads_as_saved_and_older_records_run_at_50_hz() {
    const RATE: u8 = 67;
    assert_eq!(field(RATE).map(|f| f.name), Some("servo.rate"));
    let saved = fixture_v1();
    let fields = entries(&encode(&saved));
    assert!(
        fields
            .iter()
            .any(|(id, value)| *id == RATE && value == &[50, 0])
    );
    let without: Vec<_> = fields
        .iter()
        .filter(|(id, _)| *id != RATE)
        .cloned()
        .collect();
    let (loaded, report) = load_stored(&stored(&without));
    assert_eq!(loaded.map(|s| s.rate), Ok(ServoRate::DEFAULT));
    assert_eq!(report.missing, FieldSet::of(&[RATE]));
    for (bytes, rate) in [
        ([77, 1], Some(333)),
        ([200, 0], Some(200)),
        ([78, 1], None),
        ([49, 0], None),
        ([0, 0], None),
    ] {
        let mut record = without.clone();
        record.push((RATE, bytes.to_vec()));
        let (loaded, report) = load_stored(&stored(&record));
        let hz = loaded.unwrap().rate.hz();
        match rate {
            Some(rate) => assert_eq!((hz, report.rejected), (rate, FieldSet::EMPTY)),
            None => assert_eq!((hz, report.rejected), (50, FieldSet::of(&[RATE]))),
        }
    }
}

/// A record saved by a firmware with a field this one does not have, at
/// any place among the others: skipped, every other field as saved.
#[test]
fn a_field_of_a_newer_firmware_is_skipped_wherever_it_is() {
    let saved = fixture_v1();
    let fields = entries(&encode(&saved));
    for at in 0..=fields.len() {
        for value in [vec![], vec![1, 2, 3, 4], vec![0xff; 50]] {
            let mut newer = fields.clone();
            newer.insert(at, (250, value));
            let (loaded, report) = load_stored(&stored(&newer));
            assert_eq!(loaded, Ok(saved), "a new field at {at}");
            assert_eq!(
                report,
                FieldReport {
                    unknown: FieldSet::of(&[250]),
                    ..FieldReport::default()
                }
            );
        }
    }
    // Fields stored in another order still load (the order is not part of
    // the layout).
    let mut shuffled = fields.clone();
    shuffled.reverse();
    assert_eq!(load_stored(&stored(&shuffled)).0, Ok(saved));
}
