//! The firmware's settings record: every field round-trips, every field's
//! validation error is typed, and damaged, older or newer records are
//! refused with a typed error (never a panic, never settings that were
//! not saved).

use idle_head_core::behaviour::{BehaviourError, MilliHertz};
use idle_head_core::command::{GestureKind, Hold, Percent};
use idle_head_core::driver::{ConfigError, DegreesPerSecond, DriverConfig};
use idle_head_core::servo::{NanosPerDegree, ServoError};
use idle_head_core::settings::{
    DecodeError, RamStorage, Record, SETTINGS_LEN, Settings, SettingsError, SettingsStorage,
    StorageError,
};
use idle_head_core::{Angle, AngleRange, Axis, Direction, Microseconds, Millis};
use proptest::prelude::RngExt as _;

/// A change to the built-in settings.
type Edit = fn(&mut Settings);

fn encode(s: &Settings) -> Vec<u8> {
    let mut buf = [0; 512];
    let n = s.encode(&mut buf).unwrap();
    buf[..n].to_vec()
}

#[test]
fn defaults_are_the_built_in_configuration_and_round_trip() {
    assert_eq!(Settings::DEFAULT.servos, DriverConfig::DEFAULT.servos);
    assert_eq!(Settings::DEFAULT.seeds, [127, 259, 8821]);
    let bytes = encode(&Settings::DEFAULT);
    assert_eq!(bytes.len(), SETTINGS_LEN);
    assert_eq!(Settings::decode(&bytes), Ok(Settings::DEFAULT));
    // A buffer one byte short is refused, not overrun.
    let mut short = vec![0; SETTINGS_LEN - 1];
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
        if s.validate(&DriverConfig::DEFAULT).is_err() {
            continue;
        }
        let bytes = encode(&s);
        assert_eq!(bytes.len(), SETTINGS_LEN);
        assert_eq!(Settings::decode(&bytes), Ok(s));
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
        // And a record of it does not load.
        assert_eq!(Settings::decode(&encode(&s)), Err(DecodeError::Invalid));
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
        s.servos[i].min_pulse = Microseconds(2600);
        assert!(matches!(
            servo(s.validate(&base).unwrap_err()),
            ServoError::PulseRangeEmpty { .. }
        ));
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
    // Every truncation and one byte more.
    for n in 0..bytes.len() {
        assert_eq!(
            Settings::decode(&bytes[..n]),
            Err(DecodeError::Malformed),
            "{n}"
        );
    }
    let mut long = bytes.clone();
    long.push(0);
    assert_eq!(Settings::decode(&long), Err(DecodeError::Malformed));
    // Bad enum bytes: the direction and the hold tag.
    let mut bad = bytes.clone();
    bad[8] = 2;
    assert_eq!(Settings::decode(&bad), Err(DecodeError::Malformed));
    // Every single-byte change: refused or a valid record, never a panic.
    let mut rng = host_tests::console::rng(12);
    let (mut refused, mut other) = (0, 0);
    for _ in 0..50_000 {
        let mut b = bytes.clone();
        let at = rng.random_range(0..b.len());
        b[at] = rng.random();
        match Settings::decode(&b) {
            Ok(s) => {
                assert!(s.validate(&DriverConfig::DEFAULT).is_ok());
                other += 1;
            }
            Err(_) => refused += 1,
        }
    }
    println!("damaged records: {refused} refused, {other} still valid settings");
    assert!(refused > 0);

    // Through a store: versions are checked before the bytes.
    let mut ram = RamStorage::<256>::new();
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
    assert_eq!(ram.load(), Err(StorageError::Invalid));
    // A store too small refuses the save.
    let mut tiny = RamStorage::<64>::new();
    assert_eq!(tiny.save(&Settings::DEFAULT), Err(StorageError::TooLong));
    assert_eq!(tiny.load(), Err(StorageError::Empty));
}
