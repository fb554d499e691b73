//! The never-repeating idle: the LCG rule, the first set, the join's
//! smoothness over many seeds, hand-over when a set is late, and the
//! never-repeat measure over an hour, against the fixed loop.
//!
//! The smoothness and never-repeat tests are long: run them with
//! `cargo test --release --test idle_stream -- --nocapture` to see the
//! figures they print.

use std::thread;

use idle_head::idle::{
    GenerateOnTake, IdleMode, IdlePlayer, IdleTiming, JOIN_FRAMES, LoopSet, LoopStream, LoopSupply,
    MAX_DRAWS, NoSupply, Pace, Paces, Spread, after_loop, join_weight,
};
use idle_head::motion::{DEFAULT_HEAD, DEFAULT_N, HeadConfig, Lcg};
use idle_head::{Axis, Microseconds, Millis, Playback};

type Set = LoopSet<DEFAULT_N>;
type Stream = LoopStream<DEFAULT_N>;

/// The boards' timing: 30 s loops of 900 samples, 20 ms frames.
fn timing() -> IdleTiming {
    let playback = Playback::new(Millis(30_000), Microseconds(20_000), DEFAULT_N).unwrap();
    IdleTiming::new(playback).unwrap()
}

/// The player of `config`'s stream in `mode`, generating on the spot.
fn player(
    config: HeadConfig,
    mode: IdleMode,
) -> IdlePlayer<Box<Set>, GenerateOnTake<Box<Set>, DEFAULT_N>> {
    let t = timing();
    let mut stream = Stream::new(config, &t);
    let mut first = Box::new(Set::new());
    stream.next_into(&mut first).unwrap();
    let supply = GenerateOnTake::new(stream, Box::new(Set::new()));
    IdlePlayer::new(first, supply, t, mode)
}

/// Frames `0..frames` of `config`'s idle in `mode`, `[pitch, roll, yaw]` in m°.
fn play(config: HeadConfig, mode: IdleMode, frames: usize) -> Vec<[i32; 3]> {
    let mut p = player(config, mode);
    (0..frames as u64)
        .map(|k| p.offsets(k).map(|a| a.millidegrees()))
        .collect()
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

    let period = t.period() as usize;
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
    let period = t.period() as usize;
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
fn a_frame_does_not_depend_on_the_frames_skipped_before_it() {
    let all = play(DEFAULT_HEAD, IdleMode::NeverRepeating, 4500);
    let mut p = player(DEFAULT_HEAD, IdleMode::NeverRepeating);
    let mut k = 0u64;
    while k < 4500 {
        assert_eq!(
            p.offsets(k).map(|a| a.millidegrees()),
            all[k as usize],
            "frame {k}"
        );
        // Skip 0 to 6 frames, through joins too.
        k += 1 + (k * 7 + 3) % 7;
    }
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
    let (loop_frames, period) = (t.loop_frames as usize, t.period() as usize);
    let mut stream = Stream::new(DEFAULT_HEAD, &t);
    let mut first = Box::new(Set::new());
    stream.next_into(&mut first).unwrap();
    let inner = GenerateOnTake::new(stream, Box::new(Set::new()));
    let mut p = IdlePlayer::new(first, Late { inner, late: 1 }, t, IdleMode::NeverRepeating);
    let frames: Vec<[i32; 3]> = (0..(period + loop_frames + 200) as u64)
        .map(|k| p.offsets(k).map(|a| a.millidegrees()))
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
        .map(|k| p.offsets(k).map(|a| a.millidegrees()))
        .collect();
    assert_eq!(frames, play(DEFAULT_HEAD, IdleMode::FixedLoop, 3000));
}

/// The ratios of a window `x`: max|d1|/P95|d1| and max|d2|/P95|d2| over
/// the whole window, then the same maxima taken over `region` only (the
/// join), still against the whole window's P95 (P95 nearest-rank, as
/// `idle_head::metrics`).
fn ratios(x: &[i32], region: std::ops::Range<usize>) -> [f64; 4] {
    let d1: Vec<i64> = x.windows(2).map(|w| i64::from(w[1] - w[0])).collect();
    let d2: Vec<i64> = d1.windows(2).map(|w| w[1] - w[0]).collect();
    let (w1, r1) = max_over_p95(&d1, region.clone());
    let (w2, r2) = max_over_p95(&d2, region);
    [w1, w2, r1, r2]
}

/// (max|v| / P95|v|, max over `region` of |v| / P95|v|).
fn max_over_p95(v: &[i64], region: std::ops::Range<usize>) -> (f64, f64) {
    let mut abs: Vec<i64> = v.iter().map(|x| x.abs()).collect();
    let local = abs[region].iter().copied().max().unwrap_or(0);
    let max = abs.iter().copied().max().unwrap_or(0);
    let rank = (abs.len() * 95).div_ceil(100) - 1;
    let p95 = (*abs.select_nth_unstable(rank).1).max(1) as f64;
    (max as f64 / p95, local as f64 / p95)
}

/// The worst ratio found and where.
#[derive(Clone, Copy, Debug, Default)]
struct Worst {
    value: f64,
    seed: u64,
    join: usize,
    axis: usize,
}

impl Worst {
    fn keep(&mut self, other: Self) {
        if other.value > self.value {
            *self = other;
        }
    }
}

/// Per measure ([`ratios`]' four), the worst and every value, for the
/// windows around joins and for each loop played alone.
#[derive(Clone, Default)]
struct Smoothness {
    join: [Worst; 4],
    alone: [Worst; 4],
    join_values: [Vec<f64>; 4],
    alone_values: [Vec<f64>; 4],
    /// Loops drawn, and discarded for their pace, over all axes; the most
    /// discarded for one loop.
    drawn: u64,
    discarded: u64,
    most_discarded: u8,
    /// Loops kept after [`MAX_DRAWS`] draws, none within the bounds.
    fallbacks: u64,
    /// Per [`STRETCHES`] and per d1, d2: the worst ratio and how many
    /// stretches are above 3.
    stretches: [[(Worst, usize); 2]; STRETCHES.len()],
}

/// Other stretches holding a join, beside the loop-length window centred
/// on it: (frames, frames before the join's start). One loop length with
/// the join a quarter and three quarters in, and two loop lengths with
/// joins 50, 1450 and 2850 frames in (two loops whole, and 150 frames of
/// each loop either side), which is why a loop must keep pace with the
/// loop two back as well as with the one it joins.
const STRETCHES: [(usize, usize); 3] = [(1500, 375), (1500, 1025), (3000, 1450)];

impl Smoothness {
    fn add(&mut self, other: &Self) {
        for i in 0..4 {
            self.join[i].keep(other.join[i]);
            self.alone[i].keep(other.alone[i]);
            self.join_values[i].extend_from_slice(&other.join_values[i]);
            self.alone_values[i].extend_from_slice(&other.alone_values[i]);
        }
        self.drawn += other.drawn;
        self.discarded += other.discarded;
        self.most_discarded = self.most_discarded.max(other.most_discarded);
        self.fallbacks += other.fallbacks;
        for (mine, theirs) in self.stretches.iter_mut().zip(&other.stretches) {
            for (m, t) in mine.iter_mut().zip(theirs) {
                m.0.keep(t.0);
                m.1 += t.1;
            }
        }
    }
}

/// The seeds the bounds were chosen on; [`SEEDS_UNSEEN`] checks them on
/// others.
const SEEDS: u64 = 1000;
const JOINS: usize = 50;

/// Frames on either side of a join counted as its region.
const MARGIN: usize = 10;

/// The first `loops` sets of `config`'s stream, each played alone for one
/// loop (from its entry, `loop_frames` frames each): their interiors; with
/// what the sets discarded (into `s`).
fn each_loop_alone(
    config: HeadConfig,
    loops: usize,
    loop_frames: usize,
    s: &mut Smoothness,
) -> Vec<[i32; 3]> {
    let t = timing();
    let mut stream = Stream::new(config, &t);
    let mut set = Set::new();
    let mut frames = Vec::with_capacity(loops * loop_frames);
    for _ in 0..loops {
        let info = stream.next_into(&mut set).unwrap();
        for d in info.discarded {
            s.drawn += 1 + u64::from(d);
            s.discarded += u64::from(d);
            s.most_discarded = s.most_discarded.max(d);
            s.fallbacks += u64::from(d + 1 == MAX_DRAWS);
        }
        let mut p = IdlePlayer::new(&set, NoSupply, t, IdleMode::FixedLoop);
        frames.extend((0..loop_frames as u64).map(|k| p.offsets(k).map(|a| a.millidegrees())));
    }
    frames
}

/// Measures seeds `from..to`: per seed, 50 joins (51 loops per axis), each
/// in the loop-length window (1500 frames) centred on it, its region
/// being the join's frames and [`MARGIN`] on either side; and each of
/// those loops played alone, one loop, with the region in its middle.
fn measure(from: u64, to: u64) -> Smoothness {
    let t = timing();
    let (loop_frames, period) = (t.loop_frames as usize, t.period() as usize);
    let join = t.join_frames as usize;
    // One loop more, for the longest stretch.
    let frames = period * (JOINS + 1) + loop_frames;
    let region = loop_frames / 2 - join / 2 - MARGIN..loop_frames / 2 + join / 2 + MARGIN;
    let mut s = Smoothness::default();
    let mut x = vec![0; loop_frames];
    for seed in from..to {
        let config = config_for(seed);
        let stream = play(config, IdleMode::NeverRepeating, frames);
        let alone = each_loop_alone(config, JOINS + 1, loop_frames, &mut s);
        for k in 1..=JOINS {
            let centre = k * period + join / 2;
            let around_join = centre - loop_frames / 2..centre + loop_frames / 2;
            let whole_loop = k * loop_frames..(k + 1) * loop_frames;
            for axis in 0..3 {
                for (source, window, worst, values) in [
                    (
                        &stream,
                        around_join.clone(),
                        &mut s.join,
                        &mut s.join_values,
                    ),
                    (
                        &alone,
                        whole_loop.clone(),
                        &mut s.alone,
                        &mut s.alone_values,
                    ),
                ] {
                    for (xi, f) in x.iter_mut().zip(&source[window]) {
                        *xi = f[axis];
                    }
                    for (i, value) in ratios(&x, region.clone()).into_iter().enumerate() {
                        worst[i].keep(Worst {
                            value,
                            seed,
                            join: k,
                            axis,
                        });
                        values[i].push(value);
                    }
                }
                for (&(len, before), found) in STRETCHES.iter().zip(&mut s.stretches) {
                    let Some(start) = (k * period).checked_sub(before) else {
                        continue;
                    };
                    let y: Vec<i32> = stream[start..start + len].iter().map(|f| f[axis]).collect();
                    for (i, value) in ratios(&y, 0..0).into_iter().take(2).enumerate() {
                        found[i].0.keep(Worst {
                            value,
                            seed,
                            join: k,
                            axis,
                        });
                        found[i].1 += usize::from(value > 3.0);
                    }
                }
            }
        }
    }
    s
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Seeds 1000 to 1999, never used to choose the bounds.
const SEEDS_UNSEEN: std::ops::Range<u64> = SEEDS..2 * SEEDS;

#[test]
fn joins_are_as_smooth_as_a_loops_interior_over_1000_seeds_and_50_joins() {
    smooth_over(0..SEEDS, true);
}

/// The same figures on seeds the bounds were not chosen on, printed and
/// not asserted (one 1500-frame stretch in 150,000 reaches 10/3 for d2:
/// see [`idle_head::idle::MAX_JOIN_TURN_RATIO`]). As long again, so run on
/// request: `cargo test --release --test idle_stream -- --ignored --nocapture`.
#[test]
#[ignore]
fn joins_on_other_seeds_measured() {
    smooth_over(SEEDS_UNSEEN, false);
}

/// Measures `seeds` ([`measure`], on two threads), prints the figures and,
/// if `check`, asserts every ratio and stretch at most 3.
#[allow(clippy::needless_range_loop)] // four measures, indexed in parallel arrays
fn smooth_over(seeds: std::ops::Range<u64>, check: bool) {
    let (from, to) = (seeds.start, seeds.end);
    let half = from + (to - from) / 2;
    let other = thread::spawn(move || measure(from, half));
    let mut all = measure(half, to);
    all.add(&other.join().unwrap());
    let names = [
        "max|d1|/P95|d1|, whole window",
        "max|d2|/P95|d2|, whole window",
        "max|d1|/P95|d1|, join region ",
        "max|d2|/P95|d2|, join region ",
    ];
    println!(
        "seeds {from} to {} x {JOINS} joins x 3 axes; frames in m°, 1500-frame windows centred on each join \
         (join region: its {} frames and {MARGIN} either side); each loop alone: one loop, region in its middle",
        to - 1,
        JOIN_FRAMES
    );
    for i in 0..4 {
        let (j, a) = (all.join[i], all.alone[i]);
        println!(
            "  {}: joins median {:.2} worst {:.2} (seed {}, join {}, {}), {} of {} above 3; each loop alone median {:.2} worst {:.2}",
            names[i],
            median(&mut all.join_values[i]),
            j.value,
            j.seed,
            j.join,
            Axis::ALL[j.axis].name(),
            all.join_values[i].iter().filter(|&&v| v > 3.0).count(),
            all.join_values[i].len(),
            median(&mut all.alone_values[i]),
            a.value,
        );
    }
    println!(
        "  loops drawn {}, discarded {} ({:.2}%), at most {} for one loop (of {MAX_DRAWS} draws); {} kept the closest",
        all.drawn,
        all.discarded,
        100.0 * all.discarded as f64 / all.drawn as f64,
        all.most_discarded,
        all.fallbacks
    );
    for (&(len, before), found) in STRETCHES.iter().zip(&all.stretches) {
        println!(
            "  {len} frames, the join {before} frames in: max|d1|/P95|d1| worst {:.2} (seed {}, join {}, {}), max|d2|/P95|d2| worst {:.2} (seed {}, join {}, {}); {} and {} above 3",
            found[0].0.value,
            found[0].0.seed,
            found[0].0.join,
            Axis::ALL[found[0].0.axis].name(),
            found[1].0.value,
            found[1].0.seed,
            found[1].0.join,
            Axis::ALL[found[1].0.axis].name(),
            found[0].1,
            found[1].1,
        );
    }
    if !check {
        return;
    }
    // Every stretch holding one or two joins: at most 3.
    for (&(len, before), found) in STRETCHES.iter().zip(&all.stretches) {
        for (i, (worst, above)) in found.iter().enumerate() {
            assert!(
                worst.value <= 3.0,
                "{len}-frame stretch, join {before} in, d{}: {above} above 3, worst {worst:?}",
                i + 1
            );
        }
    }
    // Every stretch holding a join, and the join itself against it: at
    // most 3 for every join, axis and seed.
    for i in 0..4 {
        assert!(
            all.join[i].value <= 3.0,
            "{}: {} windows above 3, worst {:?}",
            names[i],
            all.join_values[i].iter().filter(|&&v| v > 3.0).count(),
            all.join[i]
        );
    }
}

/// The never-repeat measure of `frames` sampled every `stride` frames,
/// with windows of `window` samples: per lag from `window` to the last
/// that leaves a window, the smallest RMS difference of two windows that
/// far apart, each axis normalised by its standard deviation. Returns the
/// pose's and each axis' minimum, each with its lag in samples.
fn never_repeat(samples: &[[i32; 3]], window: usize) -> ((f64, usize), [(f64, usize); 3]) {
    let n = samples.len();
    let sigma2: [f64; 3] = std::array::from_fn(|a| {
        let mean = samples.iter().map(|s| f64::from(s[a])).sum::<f64>() / n as f64;
        samples
            .iter()
            .map(|s| (f64::from(s[a]) - mean).powi(2))
            .sum::<f64>()
            / n as f64
    });
    let inv: [f64; 3] = sigma2.map(|s| 1.0 / (s * window as f64));
    let lags: Vec<usize> = (window..=n - window).collect();
    let run = |lags: &[usize]| {
        let mut pose = (f64::MAX, 0);
        let mut axes = [(f64::MAX, 0); 3];
        let mut d = vec![[0i64; 3]; n];
        for &lag in lags {
            let m = n - lag;
            for t in 0..m {
                for a in 0..3 {
                    let x = i64::from(samples[t][a] - samples[t + lag][a]);
                    d[t][a] = x * x;
                }
            }
            // Sliding sums, exact in integers.
            let mut sum = [0i64; 3];
            for t in 0..m {
                for a in 0..3 {
                    sum[a] += d[t][a];
                }
                if t + 1 >= window {
                    let norm: [f64; 3] = std::array::from_fn(|a| sum[a] as f64 * inv[a]);
                    let p = (norm[0] + norm[1] + norm[2]) / 3.0;
                    if p < pose.0 {
                        pose = (p, lag);
                    }
                    for a in 0..3 {
                        if norm[a] < axes[a].0 {
                            axes[a] = (norm[a], lag);
                        }
                        sum[a] -= d[t + 1 - window][a];
                    }
                }
            }
        }
        (pose, axes)
    };
    let (even, odd): (Vec<usize>, Vec<usize>) = lags.iter().partition(|&&l| l % 2 == 0);
    let (a, b) = thread::scope(|s| {
        let h = s.spawn(|| run(&even));
        let b = run(&odd);
        (h.join().unwrap(), b)
    });
    let pick = |x: (f64, usize), y: (f64, usize)| if x.0 <= y.0 { x } else { y };
    let pose = pick(a.0, b.0);
    let axes = std::array::from_fn(|i| pick(a.1[i], b.1[i]));
    let root = |(v, lag): (f64, usize)| (v.sqrt(), lag);
    (root(pose), axes.map(root))
}

#[test]
fn never_repeats_over_an_hour_and_the_fixed_loop_does() {
    // One hour of frames at 50 Hz, sampled at 10 Hz; 10 s windows.
    const FRAMES: usize = 180_000;
    const STRIDE: usize = 5;
    const WINDOW: usize = 100;
    let secs = |lag: usize| lag as f64 * STRIDE as f64 * 0.02;
    let mut results = vec![];
    for mode in [IdleMode::NeverRepeating, IdleMode::FixedLoop] {
        let frames = play(DEFAULT_HEAD, mode, FRAMES);
        let samples: Vec<[i32; 3]> = frames.iter().step_by(STRIDE).copied().collect();
        let (pose, axes) = never_repeat(&samples, WINDOW);
        println!(
            "{mode:?}: smallest windowed RMS difference over lags 10 s to 1 h: pose {:.3} at {:.1} s; pitch {:.3} at {:.1} s, roll {:.3} at {:.1} s, yaw {:.3} at {:.1} s",
            pose.0,
            secs(pose.1),
            axes[0].0,
            secs(axes[0].1),
            axes[1].0,
            secs(axes[1].1),
            axes[2].0,
            secs(axes[2].1)
        );
        results.push((pose, axes));
    }
    let (pose, axes) = results[0];
    assert!(pose.0 >= 0.15, "never-repeating pose {pose:?}");
    for a in axes {
        assert!(a.0 >= 0.02, "never-repeating axis {a:?}");
    }
    // The fixed loop replays exactly every 30 s (300 samples).
    let (pose, axes) = results[1];
    assert!(pose.0 < 1e-9 && pose.1 % 300 == 0, "fixed loop {pose:?}");
    assert!(axes.iter().all(|a| a.0 < 1e-9));
}
