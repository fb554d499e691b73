//! The join's smoothness over many seeds: loop-length and longer stretches
//! around each join against their own P95, and each loop alone.

use std::thread;

use idle_head_core::Axis;
use idle_head_core::idle::{IdleMode, IdlePlayer, LoopSupply, MAX_DRAWS, NoSupply};
use idle_head_core::motion::HeadConfig;

use super::{FRAME_US, Set, Stream, config_for, played, timing};

/// The ratios of a window `x`: max|d1|/P95|d1| and max|d2|/P95|d2| over
/// the whole window, then the same maxima taken over `region` only (the
/// join), still against the whole window's P95 (P95 nearest-rank, as
/// `idle_head_core::metrics`).
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

/// The first `count` sets of `config`'s stream, what they discarded
/// counted into `s` for the first `counted`.
fn sets(config: HeadConfig, count: usize, counted: usize, s: &mut Smoothness) -> Vec<Set> {
    let mut stream = Stream::new(config, &timing());
    let mut sets = Vec::with_capacity(count);
    for number in 0..count {
        let mut set = Set::new();
        let info = stream.next_into(&mut set).unwrap();
        sets.push(set);
        if number >= counted {
            continue;
        }
        for d in info.discarded {
            s.drawn += 1 + u64::from(d);
            s.discarded += u64::from(d);
            s.most_discarded = s.most_discarded.max(d);
            s.fallbacks += u64::from(d + 1 == MAX_DRAWS);
        }
    }
    sets
}

/// Sets generated already, handed to the player in order: the stream
/// [`super::play`] would generate on each take, generated once here for
/// both the stream and each loop alone.
struct Prepared<'a>(std::slice::Iter<'a, Set>);

impl<'a> LoopSupply<&'a Set> for Prepared<'a> {
    fn take(&mut self) -> Option<&'a Set> {
        Some(
            self.0
                .next()
                .expect("the stream took more sets than prepared"),
        )
    }

    fn give_back(&mut self, _: &'a Set) {}
}

/// Measures seeds `from..to`: per seed, 50 joins (51 loops per axis), each
/// in the loop-length window (1500 frames) centred on it, its region
/// being the join's frames and [`MARGIN`] on either side; and each of
/// those loops played alone, one loop, with the region in its middle.
fn measure(from: u64, to: u64) -> Smoothness {
    let t = timing();
    let frames_of = |us: u64| (us / FRAME_US) as usize;
    let (loop_frames, period) = (frames_of(t.loop_us), frames_of(t.period_us()));
    let join = frames_of(t.join_us);
    // One loop more, for the longest stretch.
    let frames = period * (JOINS + 1) + loop_frames;
    let region = loop_frames / 2 - join / 2 - MARGIN..loop_frames / 2 + join / 2 + MARGIN;
    let mut s = Smoothness::default();
    let mut x = vec![0; loop_frames];
    for seed in from..to {
        // The stream takes a set at each of its joins: JOINS + 2 at most.
        let sets = sets(config_for(seed), JOINS + 3, JOINS + 1, &mut s);
        let supply = Prepared(sets[1..].iter());
        let mut p = IdlePlayer::new(&sets[0], supply, t, IdleMode::NeverRepeating);
        let stream = played(&mut p, frames);
        // Each of the first JOINS + 1 sets played alone, one loop from its entry.
        let mut alone = Vec::with_capacity((JOINS + 1) * loop_frames);
        for set in &sets[..=JOINS] {
            let mut p = IdlePlayer::new(set, NoSupply, t, IdleMode::FixedLoop);
            alone.extend(played(&mut p, loop_frames));
        }
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

/// Measures the seeds ([`measure`], on two threads), prints the figures
/// and asserts every ratio and stretch at most 3.
#[test]
#[allow(clippy::needless_range_loop)] // four measures, indexed in parallel arrays
fn joins_are_as_smooth_as_a_loops_interior_over_1000_seeds_and_50_joins() {
    let (from, to) = (0, SEEDS);
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
        timing().join_us / FRAME_US
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
