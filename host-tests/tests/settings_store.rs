//! The settings store on sequential-storage's mock flash: round trips,
//! versions, records with fields added or unknown, a power cut at every
//! byte of hundreds of saves in a row of the firmware's own [`Settings`]
//! record, and random corruption.
//!
//! `cargo test settings_store:: -- --nocapture` prints the figures.

use embedded_storage_async::nor_flash::{NorFlash, ReadNorFlash};
use futures::executor::block_on;
use idle_head_core::command::{GestureKind, Percent};
use idle_head_core::servo::{NanosPerDegree, ServoCalibration};
use idle_head_core::settings::{
    DecodeError, EncodeError, FieldReport, RawRecord, Record, SETTINGS_BUFFER, SaveError,
    SectorWise, Settings, SettingsStore, StorageError, decode_postcard, encode_postcard,
};
use idle_head_core::{Angle, AngleRange, Axis, Direction, Microseconds, Millis};
use proptest::prelude::RngExt as _;
use proptest::test_runner::TestRng;
use sequential_storage::mock_flash::{MockFlashBase, MockFlashError, WriteCountCheck};
use serde::{Deserialize, Serialize};

/// Four 1 KiB pages of 4-byte words (the RP2040's flash reads in words;
/// small pages make the store turn pages over often).
type Flash = MockFlashBase<4, 4, 256>;
type Store<R> = SettingsStore<Flash, R, SETTINGS_BUFFER>;

/// A record like the firmware's settings: three servo calibrations and a
/// few integers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct ServoSettings {
    servos: [ServoCalibration; 3],
    idle_amp: Percent,
    seed: u32,
    fade: Millis,
}

/// The stored layout: plain integers, independent of the in-memory types.
#[derive(Serialize, Deserialize)]
struct ServoWire {
    neutral_us: u32,
    per_degree_ns: u32,
    reversed: bool,
    min_us: u32,
    max_us: u32,
    limits_mdeg: [i32; 2],
}

#[derive(Serialize, Deserialize)]
struct SettingsWire {
    servos: [ServoWire; 3],
    idle_amp: u8,
    seed: u32,
    fade_ms: u32,
}

impl Record for ServoSettings {
    const VERSION: u16 = 2;
    type Invalid = ();

    fn encode(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        let wire = SettingsWire {
            servos: self.servos.map(|c| ServoWire {
                neutral_us: c.neutral.0,
                per_degree_ns: c.per_degree.0,
                reversed: c.direction == Direction::Reversed,
                min_us: c.min_pulse.0,
                max_us: c.max_pulse.0,
                limits_mdeg: [c.limits.min.millidegrees(), c.limits.max.millidegrees()],
            }),
            idle_amp: self.idle_amp.get(),
            seed: self.seed,
            fade_ms: self.fade.0,
        };
        encode_postcard(&wire, buf)
    }

    fn decode(version: u16, bytes: &[u8], _: &mut FieldReport) -> Result<Self, DecodeError<()>> {
        if version != Self::VERSION {
            return Err(DecodeError::Version);
        }
        let wire: SettingsWire = decode_postcard(bytes)?;
        let servos = wire.servos.map(|w| ServoCalibration {
            neutral: Microseconds(w.neutral_us),
            per_degree: NanosPerDegree(w.per_degree_ns),
            direction: if w.reversed {
                Direction::Reversed
            } else {
                Direction::Normal
            },
            min_pulse: Microseconds(w.min_us),
            max_pulse: Microseconds(w.max_us),
            limits: AngleRange {
                min: Angle::from_millidegrees(w.limits_mdeg[0]),
                max: Angle::from_millidegrees(w.limits_mdeg[1]),
            },
        });
        if servos.iter().any(|c| c.validate().is_err()) {
            return Err(DecodeError::Invalid(()));
        }
        Ok(Self {
            servos,
            idle_amp: Percent::new(wire.idle_amp).ok_or(DecodeError::Invalid(()))?,
            seed: wire.seed,
            fade: Millis(wire.fade_ms),
        })
    }
}

/// Bytes stored under any version, to plant records of other layouts.
type Raw<const V: u16> = RawRecord<V, 1024>;

/// `bytes` as a raw record.
fn raw<const V: u16>(bytes: &[u8]) -> Raw<V> {
    Raw::new(bytes).expect("at most 1024 bytes")
}

/// Valid settings, every field varied.
fn random_settings(rng: &mut TestRng) -> ServoSettings {
    let servos = Axis::ALL.map(|axis| {
        loop {
            let mut c = ServoCalibration::hobby(axis);
            c.neutral = Microseconds(rng.random_range(1400..=1600));
            c.per_degree = NanosPerDegree(rng.random_range(9_000..=13_000));
            c.min_pulse = Microseconds(rng.random_range(500..=1000));
            c.max_pulse = Microseconds(rng.random_range(2000..=2500));
            if rng.random_bool(0.5) {
                c.direction = Direction::Reversed;
            }
            let limits = axis.anatomical_limits();
            c.limits = AngleRange {
                min: Angle::from_millidegrees(rng.random_range(limits.min.millidegrees()..=0)),
                max: Angle::from_millidegrees(rng.random_range(0..=limits.max.millidegrees())),
            };
            if c.validate().is_ok() {
                break c;
            }
        }
    });
    ServoSettings {
        servos,
        idle_amp: Percent::new(rng.random_range(0..=100)).unwrap(),
        seed: rng.random(),
        fade: Millis(rng.random_range(0..=5000)),
    }
}

/// The firmware's own settings record, servos, idle amplitude, gaze and
/// seeds varied (valid by construction, checked).
fn random_real(rng: &mut TestRng) -> Settings {
    loop {
        let s = random_real_candidate(rng);
        // Narrow random limits can leave no room for the default gestures.
        if s.validate(&idle_head_core::DriverConfig::DEFAULT).is_ok() {
            return s;
        }
    }
}

fn random_real_candidate(rng: &mut TestRng) -> Settings {
    let servos = random_settings(rng).servos;
    let mut s = Settings {
        servos,
        ..Settings::DEFAULT
    };
    s.behaviour.idle.amplitude = Percent::new(rng.random_range(0..=100)).unwrap();
    s.behaviour.gaze.base = Millis(rng.random_range(0..=5000));
    s.behaviour.defaults_mut(GestureKind::Nod).intensity =
        Percent::new(rng.random_range(0..=100)).unwrap();
    s.seeds = [rng.random(), rng.random(), rng.random()];
    s
}

fn rng(seed: u64) -> TestRng {
    host_tests::console::rng(seed)
}

fn fresh(check: WriteCountCheck) -> Flash {
    Flash::new(check, None, true)
}

fn store<R: Record>(flash: Flash) -> Store<R> {
    Store::new(flash, Flash::FULL_FLASH_RANGE).expect("a valid range")
}

/// The record a load gives, without its report.
fn load<F, R, const BUF: usize>(
    s: &mut SettingsStore<F, R, BUF>,
) -> Result<R, StorageError<F::Error, R::Invalid>>
where
    F: NorFlash,
    R: Record,
{
    block_on(s.load()).map(|loaded| loaded.record)
}

#[test]
fn round_trip_and_what_a_load_reports() {
    let mut rng = rng(1);
    let mut s = store::<ServoSettings>(fresh(WriteCountCheck::OnceOnly));
    assert_eq!(load(&mut s), Err(StorageError::Empty));
    for _ in 0..200 {
        let settings = random_settings(&mut rng);
        block_on(s.save(&settings)).unwrap();
        assert_eq!(load(&mut s), Ok(settings));
    }
    let valid = random_settings(&mut rng);
    let mut encoded = [0; 128];
    let len = valid.encode(&mut encoded).unwrap();
    let encoded = &encoded[..len];

    // Records of other layouts, planted in the same flash.
    let plant = |flash: Flash, raw: &[u8], version: u16| -> Store<ServoSettings> {
        let flash = match version {
            1 => save_raw::<1>(flash, raw),
            2 => save_raw::<2>(flash, raw),
            _ => save_raw::<3>(flash, raw),
        };
        store(flash)
    };
    let mut s = plant(s.into_flash(), encoded, 1);
    assert_eq!(load(&mut s), Err(StorageError::Older { found: 1 }));
    let mut s = plant(s.into_flash(), encoded, 3);
    assert_eq!(load(&mut s), Err(StorageError::Newer { found: 3 }));
    let mut s = plant(s.into_flash(), &[0xff, 0xff, 0xff], 2);
    assert_eq!(load(&mut s), Err(StorageError::Corrupt));
    let mut trailing = encoded.to_vec();
    trailing.push(0);
    let mut s = plant(s.into_flash(), &trailing, 2);
    assert_eq!(load(&mut s), Err(StorageError::Corrupt));
    let mut s = plant(s.into_flash(), &[], 2);
    assert_eq!(load(&mut s), Err(StorageError::Corrupt));
    let mut invalid = valid;
    invalid.servos[1].neutral = Microseconds(3000);
    let mut bytes = [0; 128];
    let n = invalid.encode(&mut bytes).unwrap();
    let mut s = plant(s.into_flash(), &bytes[..n], 2);
    assert_eq!(load(&mut s), Err(StorageError::Invalid(())));
    // A save puts things right.
    block_on(s.save(&valid)).unwrap();
    assert_eq!(load(&mut s), Ok(valid));
    block_on(s.erase()).unwrap();
    assert_eq!(load(&mut s), Err(StorageError::Empty));

    // A record too long for the work buffer is refused, nothing changes.
    let mut long = store::<Raw<2>>(fresh(WriteCountCheck::OnceOnly));
    assert_eq!(
        block_on(long.save(&raw::<2>(&[7; SETTINGS_BUFFER]))),
        Err(SaveError::TooLong)
    );
    assert!(matches!(load(&mut long), Err(StorageError::Empty)));
}

fn save_raw<const V: u16>(flash: Flash, bytes: &[u8]) -> Flash {
    let mut s = store::<Raw<V>>(flash);
    block_on(s.save(&raw::<V>(bytes))).unwrap();
    s.into_flash()
}

/// Saves in a row, each one cut at every byte it writes or erases.
const SAVES: usize = 300;

#[test]
fn a_power_cut_at_every_byte_leaves_the_old_or_the_new_record() {
    let mut rng = rng(2);
    let mut flash = fresh(WriteCountCheck::OnceOnly);
    let mut old: Option<Settings> = None;
    let (mut cuts, mut kept_old, mut got_new, mut longest) = (0_u64, 0_u64, 0_u64, 0);
    for i in 0..SAVES {
        let new = random_real(&mut rng);
        // Now and then go on from a state a cut and its repair left.
        let mut resume: Option<Flash> = None;
        let mut cut = 0;
        let done = loop {
            let mut trial = flash.clone();
            trial.bytes_until_shutoff = Some(cut);
            let mut s = store::<Settings>(trial);
            match block_on(s.save(&new)) {
                Ok(()) => break s.into_flash(),
                Err(SaveError::Flash(MockFlashError::EarlyShutoff(..))) => {}
                Err(e) => panic!("save {i}, cut at byte {cut}: {e:?}"),
            }
            // Power back: a new store over what the flash holds.
            let mut after = s.into_flash();
            after.bytes_until_shutoff = None;
            let mut s = store::<Settings>(after);
            match (load(&mut s), old) {
                (Ok(r), _) if r == new => got_new += 1,
                (Ok(r), Some(o)) if r == o => kept_old += 1,
                (Err(StorageError::Empty), None) => kept_old += 1,
                (other, _) => panic!("save {i}, cut at byte {cut}: loaded {other:?}"),
            }
            // The store works on from there.
            block_on(s.save(&new)).unwrap_or_else(|e| panic!("save {i}, cut {cut}: {e:?}"));
            assert_eq!(load(&mut s), Ok(new), "save {i}, cut {cut}");
            if rng.random_range(0..=cut) == 0 {
                resume = Some(s.into_flash());
            }
            cut += 1;
            cuts += 1;
        };
        longest = longest.max(cut);
        flash = match resume {
            Some(recovered) if i % 5 == 4 => recovered,
            _ => done,
        };
        flash.bytes_until_shutoff = None;
        old = Some(new);
    }
    println!(
        "power cuts: {SAVES} saves in a row, {cuts} cut points (every byte written or erased; \
         up to {longest} in one save), {} loads after a cut: {kept_old} old record, \
         {got_new} new record, 0 other; each followed by a save and a load of the new record",
        kept_old + got_new
    );
    assert_eq!(kept_old + got_new, cuts);
    // Every cut before the record's last byte leaves the old record. A cut
    // can only leave the new one where the store writes after the record
    // (a page closed behind it), which depends on the record's length: the
    // count is printed, not required.
    assert!(kept_old > 0);
    // Page turnovers (an erase of 1 KiB) were among the cut saves.
    assert!(longest > 1024);
}

/// Damaged flash never panics the store and never yields a record that
/// was not saved; a save afterwards puts it right.
#[test]
fn random_corruption_never_panics_nor_invents_a_record() {
    const TRIALS: usize = 20_000;
    let mut rng = rng(3);
    // Real NOR flash: writing over written bits clears them (no mock check).
    let mut histories = Vec::new();
    for saves in [1, 3, 20, 60] {
        let mut s = store::<Settings>(fresh(WriteCountCheck::Disabled));
        let saved: Vec<Settings> = (0..saves).map(|_| random_real(&mut rng)).collect();
        for r in &saved {
            block_on(s.save(r)).unwrap();
        }
        histories.push((s.into_flash(), saved));
    }
    let (mut newest, mut older, mut empty, mut corrupt, mut resaved) = (0, 0, 0, 0, 0);
    for trial in 0..TRIALS {
        let (base, saved) = &histories[trial % histories.len()];
        let mut flash = base.clone();
        corrupt_bytes(flash.as_bytes_mut(), &mut rng);
        let mut s = store::<Settings>(flash);
        match load(&mut s) {
            Ok(r) if Some(&r) == saved.last() => newest += 1,
            Ok(r) if saved.contains(&r) => older += 1,
            Err(StorageError::Empty) => empty += 1,
            Err(StorageError::Corrupt) => corrupt += 1,
            other => panic!("trial {trial}: {other:?}"),
        }
        let next = random_real(&mut rng);
        let saved_ok = block_on(s.save(&next));
        let loaded = load(&mut s);
        if saved_ok.is_ok() && loaded == Ok(next) {
            resaved += 1;
        } else {
            panic!("trial {trial}: save {saved_ok:?}, then load {loaded:?}");
        }
    }
    println!(
        "corruption: {TRIALS} damaged flashes: load gave the newest record {newest}, an older \
         one {older}, empty {empty}, corrupt {corrupt}, a record never saved 0, panics 0; \
         a save afterwards stored and loaded back in {resaved}"
    );
    assert_eq!(newest + older + empty + corrupt, TRIALS);
    assert!(older > 0 && corrupt + empty > 0);
}

/// Flips bits, overwrites bytes, clears or erases a run; mostly where
/// something is written.
fn corrupt_bytes(bytes: &mut [u8], rng: &mut TestRng) {
    let written: Vec<usize> = (0..bytes.len()).filter(|&i| bytes[i] != 0xff).collect();
    for _ in 0..rng.random_range(1..=4) {
        let at = if rng.random_bool(0.8) {
            written[rng.random_range(0..written.len())]
        } else {
            rng.random_range(0..bytes.len())
        };
        match rng.random_range(0..4) {
            0 => bytes[at] ^= 1 << rng.random_range(0..8),
            1 => bytes[at] = rng.random(),
            2 => {
                let end = (at + rng.random_range(1..64)).min(bytes.len());
                bytes[at..end].fill(0);
            }
            _ => {
                let end = (at + rng.random_range(1..64)).min(bytes.len());
                bytes[at..end].fill(0xff);
            }
        }
    }
}

/// Sectors that another firmware wrote (a board that ran something else
/// first: its file system, its code), never a store of this one: a load
/// finds nothing to use and a save takes the sectors over. Both on the
/// geometry of the other tests and on the Pico's (4 KiB sectors, bytes
/// written one at a time).
#[test]
fn foreign_data_is_taken_over_by_a_save() {
    foreign_data_on::<4, 4, 256>();
    foreign_data_on::<4, 1, 4096>();
}

fn foreign_data_on<const PAGES: usize, const WORD: usize, const WORDS: usize>() {
    let mut rng = rng(4);
    let size = PAGES * WORD * WORDS;
    let patterns: [(&str, Vec<u8>); 4] = [
        ("noise", (0..size).map(|_| rng.random()).collect()),
        ("zeros", vec![0; size]),
        ("a repeated word", [0x12, 0x34, 0x56, 0x78].repeat(size / 4)),
        (
            "noise with erased runs",
            (0..size)
                .map(|i| {
                    if (i / 512) % 2 == 0 {
                        0xff
                    } else {
                        rng.random()
                    }
                })
                .collect(),
        ),
    ];
    for (what, bytes) in patterns {
        let mut flash =
            MockFlashBase::<PAGES, WORD, WORDS>::new(WriteCountCheck::Disabled, None, true);
        flash.as_bytes_mut().copy_from_slice(&bytes);
        let range = MockFlashBase::<PAGES, WORD, WORDS>::FULL_FLASH_RANGE;
        let mut s: SettingsStore<_, Settings, SETTINGS_BUFFER> =
            SettingsStore::new(flash, range).expect("a valid range");
        let loaded = load(&mut s);
        assert!(
            matches!(loaded, Err(StorageError::Empty | StorageError::Corrupt)),
            "{what} ({WORD}-byte words, {} B pages): load gave {loaded:?}",
            WORD * WORDS
        );
        let next = random_real(&mut rng);
        assert_eq!(
            block_on(s.save(&next)),
            Ok(()),
            "{what} ({WORD}-byte words, {} B pages): save",
            WORD * WORDS
        );
        assert_eq!(load(&mut s), Ok(next), "{what}: load after the save");
    }
}

/// A flash that records the erases it is asked for.
struct Erases<F> {
    flash: F,
    calls: Vec<(u32, u32)>,
}

impl<F: embedded_storage_async::nor_flash::ErrorType> embedded_storage_async::nor_flash::ErrorType
    for Erases<F>
{
    type Error = F::Error;
}

impl<F: ReadNorFlash> ReadNorFlash for Erases<F> {
    const READ_SIZE: usize = F::READ_SIZE;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.flash.read(offset, bytes).await
    }

    fn capacity(&self) -> usize {
        self.flash.capacity()
    }
}

impl<F: NorFlash> NorFlash for Erases<F> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.calls.push((from, to));
        self.flash.erase(from, to).await
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.flash.write(offset, bytes).await
    }
}

/// Erasing the whole store goes one sector at a time through
/// `SectorWise` (the Pico's flash keeps its interrupts off for each erase
/// call), in one call without it; the store works the same over it.
#[test]
fn sector_wise_erases_one_sector_per_call() {
    let pages = Flash::FULL_FLASH_RANGE;
    let sector = u32::try_from(<Flash as NorFlash>::ERASE_SIZE).unwrap();
    let whole = |flash: Flash| Erases {
        flash,
        calls: Vec::new(),
    };
    let mut plain: SettingsStore<_, Settings, SETTINGS_BUFFER> =
        SettingsStore::new(whole(fresh(WriteCountCheck::OnceOnly)), pages.clone()).unwrap();
    block_on(plain.erase()).unwrap();
    assert_eq!(plain.flash().calls, [(pages.start, pages.end)]);

    let mut split: SettingsStore<_, Settings, SETTINGS_BUFFER> = SettingsStore::new(
        SectorWise(whole(fresh(WriteCountCheck::OnceOnly))),
        pages.clone(),
    )
    .unwrap();
    let mut rng = rng(5);
    let first = random_real(&mut rng);
    block_on(split.save(&first)).unwrap();
    block_on(split.erase()).unwrap();
    let expected: Vec<(u32, u32)> = pages
        .clone()
        .step_by(sector as usize)
        .map(|at| (at, at + sector))
        .collect();
    assert_eq!(split.flash().0.calls, expected);
    assert_eq!(load(&mut split), Err(StorageError::Empty));
    for _ in 0..50 {
        let next = random_real(&mut rng);
        block_on(split.save(&next)).unwrap();
        assert_eq!(load(&mut split), Ok(next));
    }
    assert!(
        split
            .flash()
            .0
            .calls
            .iter()
            .all(|(from, to)| to - from == sector),
        "every erase one sector"
    );
    // A range that is not whole sectors goes to the flash as asked.
    let mut odd = SectorWise(whole(fresh(WriteCountCheck::Disabled)));
    assert!(block_on(odd.erase(1, sector + 1)).is_err());
    assert_eq!(odd.0.calls, [(1, sector + 1)]);
}

/// A record longer than the work buffer (a newer firmware with many more
/// fields): a typed error, and the next save starts the store afresh.
#[test]
fn a_record_longer_than_the_buffer_is_refused_and_saved_over() {
    let big = vec![0; SETTINGS_BUFFER + 100];
    let mut newer: SettingsStore<_, Raw<2>, 1024> =
        SettingsStore::new(fresh(WriteCountCheck::OnceOnly), Flash::FULL_FLASH_RANGE).unwrap();
    block_on(newer.save(&raw::<2>(&big))).unwrap();
    let mut s = store::<Settings>(newer.into_flash());
    match block_on(s.load()) {
        Err(StorageError::TooLong { needs: Some(needs) }) => {
            assert!(needs > SETTINGS_BUFFER, "{needs}")
        }
        other => panic!("{other:?}"),
    }
    let mut rng = rng(7);
    let next = random_real(&mut rng);
    assert_eq!(block_on(s.save(&next)), Ok(()));
    assert_eq!(load(&mut s), Ok(next));
    let mut again = store::<Settings>(s.into_flash());
    assert_eq!(load(&mut again), Ok(next));
}
