//! A record of layout version 1, and the flash sectors a version 1
//! firmware wrote (the fixtures in `fixtures/`), load intact; a damaged one
//! is refused.

use super::*;

/// The settings in the version 1 fixture (`fixtures/README.md`).
pub(crate) fn fixture_v1() -> Settings {
    let mut s = Settings::DEFAULT;
    let p = |v| Percent::new(v).unwrap();
    let us = Microseconds;
    let mdeg = Angle::from_millidegrees;
    let servo = |neutral, per_degree, direction, min, max, limits: [i32; 2]| {
        idle_head_core::servo::ServoCalibration {
            neutral: us(neutral),
            per_degree: NanosPerDegree(per_degree),
            direction,
            min_pulse: us(min),
            max_pulse: us(max),
            limits: AngleRange {
                min: mdeg(limits[0]),
                max: mdeg(limits[1]),
            },
        }
    };
    s.servos = [
        servo(
            1520,
            10_800,
            Direction::Reversed,
            900,
            2100,
            [-25_500, 18_250],
        ),
        servo(
            1480,
            11_600,
            Direction::Normal,
            950,
            2050,
            [-20_000, 21_000],
        ),
        servo(
            1510,
            9_900,
            Direction::Reversed,
            800,
            2200,
            [-40_000, 35_000],
        ),
    ];
    let b = &mut s.behaviour;
    let gesture =
        |amplitude, cycles, slow, brisk, intensity| idle_head_core::behaviour::GestureDefaults {
            amplitude: mdeg(amplitude),
            cycles,
            slow: MilliHertz(slow),
            brisk: MilliHertz(brisk),
            intensity: p(intensity),
        };
    *b.defaults_mut(GestureKind::Nod) = gesture(5_500, 3, 1_400, 3_200, 40);
    *b.defaults_mut(GestureKind::Shake) = gesture(7_250, 4, 1_100, 2_400, 65);
    *b.defaults_mut(GestureKind::Tilt) = gesture(9_000, 2, 450, 1_100, 30);
    b.max_frequency = MilliHertz(3_800);
    b.longest_gesture = Millis(9_000);
    b.blend = Millis(300);
    b.gaze.base = Millis(280);
    b.gaze.per_degree = Millis(9);
    b.gaze.hold = Hold::Return(Millis(2_500));
    b.gaze.longest = Millis(7_000);
    b.idle.amplitude = p(85);
    b.idle.duck = p(55);
    b.idle.fade = Millis(1_200);
    for (limits, (speed, accel)) in
        b.gesture_limits
            .iter_mut()
            .zip([(240, 4_800), (230, 4_600), (220, 4_400)])
    {
        limits.max_speed = DegreesPerSecond(speed);
        limits.max_accel = DegreesPerSecondSquared(accel);
    }
    b.settle = Millis(600);
    s.seeds = [42, 1_013_904_216, 3_000_000_001];
    // Seeds other than the paper's: chosen, and kept so.
    s.seeding = idle_head_core::seed::Seeding::Chosen;
    s
}

/// The fixture's record, as `RamStorage` kept it: `01 00`, then 192 bytes.
pub(crate) const V1_RECORD: &[u8] = include_bytes!("../../fixtures/settings-v1-record.bin");
/// The Pico's four settings sectors after two saves of version 1.
const V1_SECTORS: &[u8] = include_bytes!("../../fixtures/settings-v1-sectors.bin");
/// The Pico's flash geometry: bytes read and written one at a time, 4 KiB
/// sectors, four of them.
type PicoSectors = MockFlashBase<4, 1, 4096>;

/// The ids of the fields version 1 had.
const V1_FIELDS: std::ops::RangeInclusive<u8> = 1..=56;

/// What a load of a version 1 record reports: the fields added since,
/// missing.
fn v1_report() -> FieldReport {
    let mut missing = FieldSet::EMPTY;
    for field in FIELDS.iter().filter(|f| !V1_FIELDS.contains(&f.id)) {
        missing.insert(field.id);
    }
    FieldReport {
        missing,
        ..FieldReport::default()
    }
}

/// The fields of version 1 whose stored bytes are the same for `a` and `b`.
fn same_fields(a: &Settings, b: &Settings) -> Vec<&'static str> {
    let (a, b) = (encode(a), encode(b));
    let entries = |bytes: &[u8]| {
        let mut out = Vec::new();
        let mut rest = bytes;
        while let [id, len, tail @ ..] = rest {
            out.push((*id, tail[..usize::from(*len)].to_vec()));
            rest = &tail[usize::from(*len)..];
        }
        out
    };
    entries(&a)
        .into_iter()
        .zip(entries(&b))
        .filter(|(x, y)| x == y && V1_FIELDS.contains(&x.0))
        .map(|((id, _), _)| FIELDS.iter().find(|f| f.id == id).unwrap().name)
        .collect()
}

#[test]
fn the_version_1_record_loads_with_every_value_intact() {
    let expected = fixture_v1();
    assert_eq!(
        expected.validate(&DriverConfig::DEFAULT).map(|_| ()),
        Ok(())
    );
    // The fixture is worth its name: only roll's direction is the built-in one.
    assert_eq!(
        same_fields(&expected, &Settings::DEFAULT),
        ["servo.roll.direction"]
    );
    assert_eq!(V1_RECORD.len(), 2 + 192);
    assert_eq!(V1_RECORD[..2], [1, 0]);
    let mut report = FieldReport::default();
    assert_eq!(
        Settings::decode(1, &V1_RECORD[2..], &mut report),
        Ok(expected)
    );
    assert_eq!(report, v1_report());
    // Through the console's storage, and saved again in today's layout.
    let mut ram = RamStorage::<{ SETTINGS_BUFFER }>::new();
    ram.set_raw(V1_RECORD).unwrap();
    assert_eq!(ram.load(), Ok(expected));
    ram.save(&expected).unwrap();
    assert_eq!(ram.raw()[..2], Settings::VERSION.to_le_bytes());
    assert_eq!(ram.load(), Ok(expected));
}

#[test]
fn the_version_1_flash_sectors_load_with_every_value_intact() {
    let mut flash = PicoSectors::new(WriteCountCheck::OnceOnly, None, true);
    assert_eq!(V1_SECTORS.len(), flash.as_bytes().len());
    flash.as_bytes_mut().copy_from_slice(V1_SECTORS);
    let mut store: SettingsStore<_, Settings, SETTINGS_BUFFER> =
        SettingsStore::new(flash, PicoSectors::FULL_FLASH_RANGE).unwrap();
    let expected = fixture_v1();
    // The newest of the two records, migrated.
    assert_eq!(
        block_on(store.load()),
        Ok(Loaded {
            record: expected,
            version: 1,
            fields: v1_report(),
        })
    );
    // A save writes today's layout after it; the next load reads that.
    let mut changed = expected;
    changed.servos[0].neutral = Microseconds(1530);
    block_on(store.save(&changed)).unwrap();
    let loaded = block_on(store.load()).unwrap();
    assert_eq!(
        (loaded.record, loaded.version),
        (changed, Settings::VERSION)
    );
    assert!(loaded.fields.is_clean());
    // A store opened afresh on those sectors (the next boot) reads the same.
    let mut again: SettingsStore<_, Settings, SETTINGS_BUFFER> =
        SettingsStore::new(store.into_flash(), PicoSectors::FULL_FLASH_RANGE).unwrap();
    assert_eq!(block_on(again.load()).map(|l| l.record), Ok(changed));
}

#[test]
fn a_damaged_version_1_record_is_refused() {
    let mut ram = RamStorage::<{ SETTINGS_BUFFER }>::new();
    // A byte short, or a byte more: not a version 1 record.
    ram.set_raw(&V1_RECORD[..V1_RECORD.len() - 1]).unwrap();
    assert_eq!(ram.load(), Err(StorageError::Corrupt));
    let mut long = V1_RECORD.to_vec();
    long.push(0);
    ram.set_raw(&long).unwrap();
    assert_eq!(ram.load(), Err(StorageError::Corrupt));
    // Pitch's neutral (bytes 2..6) far outside its pulse range: refused
    // with the reason.
    let mut bad = V1_RECORD.to_vec();
    bad[2..6].copy_from_slice(&3000_u32.to_le_bytes());
    ram.set_raw(&bad).unwrap();
    assert!(matches!(
        ram.load(),
        Err(StorageError::Invalid(SettingsError::Driver(
            ConfigError::Servo {
                axis: Axis::Pitch,
                error: ServoError::NeutralOutsidePulseRange { .. }
            }
        )))
    ));
    // Roll's direction byte (2 + 25 + 8) out of range: that field's default.
    let mut direction = V1_RECORD.to_vec();
    direction[2 + 25 + 8] = 7;
    let mut report = FieldReport::default();
    let loaded = Settings::decode(1, &direction[2..], &mut report).unwrap();
    assert_eq!(loaded, fixture_v1());
    assert_eq!(report.rejected.iter().collect::<Vec<_>>(), [10]);
}
