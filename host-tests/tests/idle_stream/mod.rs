//! The never-repeating idle: the LCG rule, the first set, the join's
//! smoothness over many seeds, hand-over when a set is late, and the
//! never-repeat measure over an hour, against the fixed loop.
//!
//! The smoothness and never-repeat tests are long: run them with
//! `cargo test --release idle_stream:: -- --nocapture` to see the
//! figures they print.

use idle_head_core::idle::{
    GenerateOnTake, IdleMode, IdlePlayer, IdleTiming, LoopSet, LoopStream, LoopSupply, NoSupply,
    Pace, Paces, Spread, after_loop, join_weight,
};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadConfig, Lcg};
use idle_head_core::{Axis, Microseconds, Millis, Playback, Timestamp};

type Set = LoopSet<DEFAULT_N>;
type Stream = LoopStream<DEFAULT_N>;

/// The frame period of the tests: 20 ms (50 Hz).
const FRAME_US: u64 = 20_000;

/// The time of frame `k`.
const fn at(k: u64) -> Timestamp {
    Timestamp(k * FRAME_US)
}

/// The boards' timing: 30 s loops of 900 samples, 20 ms frames.
fn timing() -> IdleTiming {
    let playback = Playback::new(Millis(30_000), Microseconds(20_000), DEFAULT_N).unwrap();
    IdleTiming::new(playback).unwrap()
}

/// The player of `config`'s stream in `mode`, generating on the spot.
type Player = IdlePlayer<Box<Set>, GenerateOnTake<Box<Set>, DEFAULT_N>>;

fn player(config: HeadConfig, mode: IdleMode) -> Player {
    let t = timing();
    let mut stream = Stream::new(config, &t);
    let mut first = Box::new(Set::new());
    stream.next_into(&mut first).unwrap();
    let supply = GenerateOnTake::new(stream, Box::new(Set::new()));
    IdlePlayer::new(first, supply, t, mode)
}

/// Frames `0..frames` of `config`'s idle in `mode`, `[pitch, roll, yaw]` in m°.
fn play(config: HeadConfig, mode: IdleMode, frames: usize) -> Vec<[i32; 3]> {
    played(&mut player(config, mode), frames)
}

/// Frames `0..frames` of the player `p`, `[pitch, roll, yaw]` in m°.
fn played<H, S>(p: &mut IdlePlayer<H, S>, frames: usize) -> Vec<[i32; 3]>
where
    H: std::ops::Deref<Target = Set>,
    S: LoopSupply<H>,
{
    (0..frames as u64)
        .map(|k| p.offsets(at(k)).map(|a| a.millidegrees()))
        .collect()
}

/// Plays `p` from frame 0 on, skipping frames (`1 + (k·7 + 3) mod skip`
/// a step), each frame it plays (at `at(k)`) checked against `all`.
fn check_skipping(mut p: Player, all: &[[i32; 3]], at: impl Fn(u64) -> Timestamp, skip: u64) {
    let mut k = 0u64;
    while k < all.len() as u64 {
        assert_eq!(
            p.offsets(at(k)).map(|a| a.millidegrees()),
            all[k as usize],
            "frame {k}"
        );
        k += 1 + (k * 7 + 3) % skip;
    }
}

/// The default configuration with three seeds drawn from `index`
/// (SplitMix64), index 0 being the default set itself.
fn config_for(index: u64) -> HeadConfig {
    let mut c = DEFAULT_HEAD;
    if index == 0 {
        return c;
    }
    // Three fresh values per index: no two indices share a seed.
    let mut z = index.wrapping_mul(3).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let mut next = || {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut x = z;
        x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (x ^ (x >> 31)) as u32
    };
    c.pitch.seed = next();
    c.roll.seed = next();
    c.yaw.seed = next();
    c
}

#[test]
fn each_seed_is_the_last_value_the_previous_loop_drew() {
    for seed in [0, 1, 127, 259, 8821, u32::MAX] {
        let mut lcg = Lcg::new(seed);
        for _ in 0..DEFAULT_N {
            lcg.next_value();
        }
        assert_eq!(after_loop(seed, DEFAULT_N), lcg.value());
        assert_eq!(after_loop(seed, 0), seed);
    }
    let t = timing();
    let mut stream = Stream::new(DEFAULT_HEAD, &t);
    let mut set = Set::new();
    let mut seeds = [127, 259, 8821];
    let mut discarded = 0;
    for number in 0..20 {
        let info = stream.next_into(&mut set).unwrap();
        assert_eq!(info.number, number);
        // A loop discarded for its pace is skipped: the next is drawn from
        // where its stream stopped.
        let kept: [u32; 3] = std::array::from_fn(|a| {
            (0..info.discarded[a]).fold(seeds[a], |s, _| after_loop(s, DEFAULT_N))
        });
        assert_eq!(info.seeds, kept);
        assert_eq!(set.seeds(), kept);
        seeds = kept.map(|s| after_loop(s, DEFAULT_N));
        assert_eq!(stream.seeds(), seeds);
        discarded += info.discarded.iter().map(|&d| u32::from(d)).sum::<u32>();
    }
    // The default stream discards some: the rule is exercised here.
    assert!(discarded > 0);
}

#[test]
fn the_first_set_is_the_boot_loops_and_plays_as_the_fixed_loop_until_the_first_join() {
    let t = timing();
    let mut stream = Stream::new(DEFAULT_HEAD, &t);
    let mut set = Set::new();
    stream.next_into(&mut set).unwrap();
    assert_eq!(set.checksum(), 0x11a5_b828);
    // Adopting a set generated on its own gives the same stream.
    let mut boot = Set::new();
    boot.generate(&DEFAULT_HEAD).unwrap();
    let mut adopted = Stream::new(DEFAULT_HEAD, &t);
    adopted.adopt(&boot);
    let (mut a, mut b) = (Set::new(), Set::new());
    let ia = stream.next_into(&mut a).unwrap();
    let ib = adopted.next_into(&mut b).unwrap();
    assert_eq!(ia, ib);
    assert_eq!(a.checksum(), b.checksum());

    let period = (t.period_us() / FRAME_US) as usize;
    let stream_frames = play(DEFAULT_HEAD, IdleMode::NeverRepeating, period + 200);
    let fixed = play(DEFAULT_HEAD, IdleMode::FixedLoop, period + 200);
    assert_eq!(stream_frames[0], [0; 3]);
    assert_eq!(stream_frames[..period], fixed[..period]);
    assert_ne!(stream_frames[period + 100..], fixed[period + 100..]);
    // The fixed loop repeats every loop exactly.
    let fixed = play(DEFAULT_HEAD, IdleMode::FixedLoop, 3100);
    assert_eq!(fixed[..1600], fixed[1500..3100]);
}

#[test]
fn join_frames_lie_between_the_two_loops_and_inside_the_ranges() {
    let t = timing();
    let period = (t.period_us() / FRAME_US) as usize;
    for index in 0..4 {
        let config = config_for(index);
        let frames = play(config, IdleMode::NeverRepeating, 6 * period);
        // The samples lie inside [α1, α2]; the spline between them may
        // overshoot by a few m°, in the fixed loop as across joins.
        for axis in Axis::ALL {
            let range = config.axis(axis).range;
            let (lo, hi) = (range.min.millidegrees() - 5, range.max.millidegrees() + 5);
            assert!(frames.iter().all(|f| (lo..=hi).contains(&f[axis.index()])));
        }
    }
    let n = 60;
    assert_eq!(join_weight(0, n), 0);
    assert_eq!(join_weight(n, n), 1 << 15);
    assert_eq!(join_weight(n + 7, n), 1 << 15);
    assert!((0..n).all(|i| join_weight(i, n) <= join_weight(i + 1, n)));
    // Symmetric: s(u) + s(1 − u) = 1, within the rounding.
    assert!((0..=n).all(|i| {
        let sum = i32::from(join_weight(i, n)) + i32::from(join_weight(n - i, n));
        (sum - (1 << 15)).abs() <= 1
    }));
    // Flat at both ends: the first and last steps are far below the middle's.
    let step = |i: usize| join_weight(i + 1, n) - join_weight(i, n);
    assert!(step(0) * 100 < step(n / 2) && step(n - 1) * 100 < step(n / 2));
}

#[test]
fn at_333_hz_a_frame_does_not_depend_on_the_frames_before_it_either() {
    // 3003 µs frames: a join's start falls between two frames; the set
    // taken over is entered where the cursor stands (no division), which
    // must be where its time puts it (located from the time, after a skip).
    let period = 3003;
    let timing_at = |t: IdleTiming| IdleTiming {
        playback: t.playback.with_frame_period(Microseconds(period)),
        ..t
    };
    let fresh = || {
        let t = timing_at(timing());
        let mut stream = Stream::new(DEFAULT_HEAD, &t);
        let mut first = Box::new(Set::new());
        stream.next_into(&mut first).unwrap();
        let supply = GenerateOnTake::new(stream, Box::new(Set::new()));
        IdlePlayer::new(first, supply, t, IdleMode::NeverRepeating)
    };
    let at = |k: u64| Timestamp(k * u64::from(period));
    // Through two joins (28 s and 56 s).
    let frames = 60_000_000 / u64::from(period);
    let mut p = fresh();
    let all: Vec<[i32; 3]> = (0..frames)
        .map(|k| p.offsets(at(k)).map(|a| a.millidegrees()))
        .collect();
    assert_eq!(p.stats().joins, 2);
    check_skipping(fresh(), &all, at, 5);
}

#[test]
fn a_frame_does_not_depend_on_the_frames_skipped_before_it() {
    let all = play(DEFAULT_HEAD, IdleMode::NeverRepeating, 4500);
    // Skip 0 to 6 frames, through joins too.
    let p = player(DEFAULT_HEAD, IdleMode::NeverRepeating);
    check_skipping(p, &all, at, 7);
}

#[test]
fn a_loops_pace_is_the_p95_and_maximum_of_its_cyclic_differences() {
    // Nearest-rank P95 and maximum by sorting, as `ratios` measures frames.
    let reference = |x: &[i16], order: usize| {
        let n = x.len();
        let v = |i: usize| i64::from(x[i % n]);
        let mut d: Vec<i64> = (0..n)
            .map(|i| match order {
                1 => (v(i + 1) - v(i)).abs(),
                _ => (v(i + 2) - 2 * v(i + 1) + v(i)).abs(),
            })
            .collect();
        d.sort_unstable();
        (d[(n * 95).div_ceil(100) - 1] as u16, d[n - 1] as u16)
    };
    let mut lcg = Lcg::new(7);
    for n in [3, 4, 20, 101, DEFAULT_N] {
        // Steps up to ±2048 m° and ±16384 m° (one to four histogram passes).
        for shift in [20, 20, 17] {
            // A bounded random walk, in m°.
            let mut x = 0i32;
            let half = 1 << (31 - shift);
            let angles: Vec<i16> = (0..n)
                .map(|_| {
                    x = (x + (lcg.next_value() >> shift) as i32 - half).clamp(-30_000, 30_000);
                    x as i16
                })
                .collect();
            let mut scratch = angles.clone();
            let pace = Pace::of(&mut scratch);
            let (p1, m1) = reference(&angles, 1);
            let (p2, m2) = reference(&angles, 2);
            assert_eq!((pace.speed.p95, pace.speed.max), (p1, m1), "n {n}");
            assert_eq!((pace.turn.p95, pace.turn.max), (p2, m2), "n {n}");
        }
    }
}

#[test]
fn a_loop_keeps_pace_with_the_last_two_loops_and_the_join_into_the_last() {
    let pace = |p1, m1, p2, m2| Pace {
        speed: Spread { p95: p1, max: m1 },
        turn: Spread { p95: p2, max: m2 },
    };
    let calm = pace(100, 150, 10, 15);
    let mid = pace(140, 190, 13, 20);
    let lively = pace(190, 260, 17, 27);
    // Neighbours keep pace (260 ≤ 2 · 140, 27 ≤ 2.25 · 13, ...), but the
    // lively loop not with the calm one (260 > 2 · 100).
    assert!(Pace::within(lively.score(mid)) && Pace::within(mid.score(calm)));
    assert!(!Pace::within(lively.score(calm)));
    let mut history = Paces::new(calm);
    assert!(Pace::within(history.score(mid)));
    history.push(mid, 0);
    // The calm loop two back still counts; once it is three back, not.
    assert!(!Pace::within(history.score(lively)));
    history.push(mid, 0);
    assert!(Pace::within(history.score(lively)));
    // The join into the last loop against the next loop's P95|d2| (13):
    // at most 2.75 times it.
    history.push(mid, 35);
    assert!(Pace::within(history.score(mid)));
    history.push(mid, 36);
    assert!(!Pace::within(history.score(mid)));
    // A new join against the smallest P95|d2| of its loop and the last two
    // (10, two back): at most 27.
    let mut history = Paces::new(calm);
    history.push(mid, 0);
    assert!(Pace::within(history.join_score(mid, 27)));
    assert!(!Pace::within(history.join_score(mid, 28)));
}

/// A supply that is not ready for its first `late` joins.
struct Late {
    inner: GenerateOnTake<Box<Set>, DEFAULT_N>,
    late: u32,
}

impl LoopSupply<Box<Set>> for Late {
    fn take(&mut self) -> Option<Box<Set>> {
        if self.late > 0 {
            self.late -= 1;
            return None;
        }
        self.inner.take()
    }

    fn give_back(&mut self, set: Box<Set>) {
        self.inner.give_back(set);
    }
}

#[test]
fn a_late_set_leaves_the_current_loop_playing_and_joins_a_loop_later() {
    let t = timing();
    let (loop_frames, period) = (
        (t.loop_us / FRAME_US) as usize,
        (t.period_us() / FRAME_US) as usize,
    );
    let mut stream = Stream::new(DEFAULT_HEAD, &t);
    let mut first = Box::new(Set::new());
    stream.next_into(&mut first).unwrap();
    let inner = GenerateOnTake::new(stream, Box::new(Set::new()));
    let mut p = IdlePlayer::new(first, Late { inner, late: 1 }, t, IdleMode::NeverRepeating);
    let frames: Vec<[i32; 3]> = (0..(period + loop_frames + 200) as u64)
        .map(|k| p.offsets(at(k)).map(|a| a.millidegrees()))
        .collect();
    let fixed = play(DEFAULT_HEAD, IdleMode::FixedLoop, frames.len());
    let on_time = play(DEFAULT_HEAD, IdleMode::NeverRepeating, period + 200);
    // One more loop of set 0, then the join that was due, on the same samples.
    assert_eq!(
        frames[..period + loop_frames],
        fixed[..period + loop_frames]
    );
    assert_eq!(frames[period + loop_frames..], on_time[period..]);
    assert_eq!(p.stats().late, 1);
    assert_eq!(p.stats().joins, 1);
    assert_eq!(p.stats().set, 1);

    // With no supply at all, the first set plays for ever.
    let mut first = Box::new(Set::new());
    first.generate(&DEFAULT_HEAD).unwrap();
    let mut p = IdlePlayer::new(first, NoSupply, t, IdleMode::NeverRepeating);
    let frames: Vec<[i32; 3]> = (0..3000u64)
        .map(|k| p.offsets(at(k)).map(|a| a.millidegrees()))
        .collect();
    assert_eq!(frames, play(DEFAULT_HEAD, IdleMode::FixedLoop, 3000));
}

mod never_repeat;
mod smoothness;
