//! The stream of loop sets: each set generated from where the last one's
//! LCG streams stopped, and entered where it joins the last one best.

use crate::axis::Axis;
use crate::motion::{
    AxisError, HeadConfig, HeadTrajectories, Integral16, LCG_A, LCG_C, LoopInfo, MAX_WINDOW,
    Sample, Trajectory,
};

use super::join::{IdleTiming, MAX_JOIN_SAMPLES, blend, join_weight};
use super::pace::{MAX_DRAWS, Pace, Paces, Spread, max_turn};
use super::supply::LoopSupply;

/// Samples of a join kept per axis: the one before it, and the join's
/// `J + 1` (see [`LoopSet`]).
const KEPT: usize = MAX_JOIN_SAMPLES + 2;

/// One loop per axis, the unit the stream hands from the generator to the
/// frame task, usable in a `static`: 3 · N · 2 bytes, and the join into it
/// (3 · 66 · 2 bytes).
///
/// The join is kept with the set: its samples `−1..=J` in playback order
/// (m°), sample −1 the outgoing loop's last before the join, samples
/// `0..=J` the outgoing loop's exit blended into this loop's entry. Read
/// through [`SetView`]s, a set plays its join and then its own loop, with
/// one player and no second loop to read.
///
/// `CAP` bounds the window W of the loops ([`HeadTrajectories`]).
#[derive(Clone, Debug)]
pub struct LoopSet<const N: usize, const CAP: usize = { MAX_WINDOW as usize }> {
    loops: HeadTrajectories<Integral16, N, CAP>,
    /// The join's samples per axis, `join[axis][m]` for playback index `m − 1`.
    join: [[i16; KEPT]; 3],
    /// How many of them there are: `J + 2`, or 0 (set 0: no join).
    join_len: u8,
    /// The seeds r(0) the loops were generated from.
    seeds: [u32; 3],
    /// Which set of its stream this is (0: the configuration's own loops).
    number: u32,
}

impl<const N: usize, const CAP: usize> LoopSet<N, CAP> {
    /// Three all-zero loops (the neutral pose).
    #[must_use]
    pub const fn new() -> Self {
        Self {
            loops: HeadTrajectories::new(),
            join: [[0; KEPT]; 3],
            join_len: 0,
            seeds: [0; 3],
            number: 0,
        }
    }

    /// Generates the configuration's own loops: set 0 of its stream, each
    /// loop entered at its neutral crossing (the fixed loops of the paper).
    ///
    /// # Errors
    /// As [`HeadTrajectories::generate`].
    pub fn generate(&mut self, config: &HeadConfig) -> Result<[LoopInfo; 3], AxisError> {
        self.number = 0;
        self.join_len = 0;
        self.seeds = Axis::ALL.map(|axis| config.axis(axis).seed);
        self.loops.generate(config)
    }

    /// The three loops.
    #[must_use]
    pub const fn trajectories(&self) -> &HeadTrajectories<Integral16, N, CAP> {
        &self.loops
    }

    /// The loops `[pitch, roll, yaw]` as they are, for playback once the
    /// join into them has been played (and for set 0).
    #[inline]
    #[must_use]
    pub const fn loops(&self) -> [&Trajectory<Integral16, N>; 3] {
        let [p, r, y] = self.loops.axes();
        [p, r, y]
    }

    /// The loops `[pitch, roll, yaw]` with the join into them, for playback
    /// while the join plays.
    #[inline]
    #[must_use]
    pub fn views(&self) -> [SetView<'_, N>; 3] {
        let len = usize::from(self.join_len).min(KEPT);
        let [p, r, y] = self.loops.axes();
        let [jp, jr, jy] = &self.join;
        [
            SetView {
                loop_: p,
                join: jp.get(..len).unwrap_or(&[]),
            },
            SetView {
                loop_: r,
                join: jr.get(..len).unwrap_or(&[]),
            },
            SetView {
                loop_: y,
                join: jy.get(..len).unwrap_or(&[]),
            },
        ]
    }

    /// The join's samples of `axis`, playback indices `−1..=J` (empty for
    /// set 0).
    #[must_use]
    pub fn join_samples(&self, axis: Axis) -> &[i16] {
        let len = usize::from(self.join_len).min(KEPT);
        &self.join[axis.index()][..len]
    }

    /// The seeds r(0) the loops were generated from.
    #[must_use]
    pub const fn seeds(&self) -> [u32; 3] {
        self.seeds
    }

    /// Which set of its stream this is (0: the configuration's own).
    #[must_use]
    pub const fn number(&self) -> u32 {
        self.number
    }

    /// Where each loop is entered (its playback start in the ring).
    #[must_use]
    pub fn starts(&self) -> [u16; 3] {
        Axis::ALL.map(|axis| self.loops.axis(axis).start() as u16)
    }

    /// The checksum of the loops ([`HeadTrajectories::checksum`]).
    #[must_use]
    pub fn checksum(&self) -> u32 {
        self.loops.checksum()
    }
}

impl<const N: usize, const CAP: usize> Default for LoopSet<N, CAP> {
    fn default() -> Self {
        Self::new()
    }
}

/// One axis of a [`LoopSet`] as a player reads it: the join's samples
/// first (playback indices `−1..=J`, the first as index N − 1), then the
/// loop's own.
#[derive(Clone, Copy, Debug)]
pub struct SetView<'a, const N: usize> {
    loop_: &'a Trajectory<Integral16, N>,
    /// The join's samples, playback indices `−1..=J`.
    join: &'a [i16],
}

impl<const N: usize> crate::playback::LoopSource for SetView<'_, N> {
    fn len(&self) -> usize {
        N
    }

    #[inline]
    fn angle(&self, index: usize) -> crate::units::Angle {
        let m = if index + 1 == N { 0 } else { index + 1 };
        match self.join.get(m) {
            Some(&kept) => crate::units::Angle::from_millidegrees(i32::from(kept)),
            None => self.loop_.angle(index),
        }
    }
}

impl<const N: usize, const CAP: usize> crate::playback::Axes for LoopSet<N, CAP> {
    type Loop = Trajectory<Integral16, N>;

    #[inline]
    fn axis(&self, index: usize) -> &Self::Loop {
        let [p, r, y] = self.loops.axes();
        match index {
            0 => p,
            1 => r,
            _ => y,
        }
    }
}

impl<'a, const N: usize> crate::playback::Axes for [SetView<'a, N>; 3] {
    type Loop = SetView<'a, N>;

    #[inline]
    fn axis(&self, index: usize) -> &Self::Loop {
        let [p, r, y] = self;
        match index {
            0 => p,
            1 => r,
            _ => y,
        }
    }
}

/// The pace of a stream with no set yet (`Pace::default`, in a `const`).
const PACE_ZERO: Pace = Pace {
    speed: Spread { p95: 0, max: 0 },
    turn: Spread { p95: 0, max: 0 },
};
/// The same for both loops a new one is measured against.
const PACES_ZERO: Paces = Paces::new(PACE_ZERO);

/// What [`LoopStream::next_into`] made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SetInfo {
    /// The set's number in the stream.
    pub number: u32,
    /// The seeds r(0) of its loops.
    pub seeds: [u32; 3],
    /// Where each loop is entered.
    pub starts: [u16; 3],
    /// Per axis, the RMS difference in m° between the outgoing loop's exit
    /// and the incoming loop over the join (sampled every
    /// [`MATCH_STRIDE`] samples): what the blend has to hide.
    pub mismatch: [u32; 3],
    /// Per axis, the loops drawn and discarded before the one kept, for
    /// not keeping pace with the axis' last two loops or joining the last
    /// too sharply ([`Paces`]).
    pub discarded: [u8; 3],
}

/// Every how many samples of the join the entry search compares.
pub const MATCH_STRIDE: usize = 3;

/// The generator of a never-repeating stream of loop sets (see the
/// [module docs](super)). It keeps the seeds of the next set and the exit
/// segment of the last one (what the next set must join), 0.4 KB.
#[derive(Clone, Debug)]
pub struct LoopStream<const N: usize> {
    config: HeadConfig,
    join_samples: usize,
    /// The seeds of the next set.
    seeds: [u32; 3],
    /// The next set's number.
    next: u32,
    /// The last set's samples at playback indices `N − J − 1 ..= N` per
    /// axis, in m°: the one before its join out, and what it plays.
    exit: [[i16; KEPT]; 3],
    /// The pace of the last two sets per axis, which the next set's loops
    /// must keep.
    pace: [Paces; 3],
}

impl<const N: usize> LoopStream<N> {
    /// The stream of `config`'s loops played with `timing`; its first set
    /// is [`LoopSet::generate`]'s.
    #[must_use]
    pub const fn new(config: HeadConfig, timing: &IdleTiming) -> Self {
        let join = timing.join_samples;
        Self {
            config,
            join_samples: if join > MAX_JOIN_SAMPLES {
                MAX_JOIN_SAMPLES
            } else {
                join
            },
            seeds: [config.pitch.seed, config.roll.seed, config.yaw.seed],
            next: 0,
            exit: [[0; KEPT]; 3],
            pace: [PACES_ZERO; 3],
        }
    }

    /// The seeds of the next set.
    #[must_use]
    pub const fn seeds(&self) -> [u32; 3] {
        self.seeds
    }

    /// Draws the next set from `seeds` instead of where the streams
    /// stopped (the console's `seed`); the streams run on from there.
    pub fn reseed(&mut self, seeds: [u32; 3]) {
        self.seeds = seeds;
    }

    /// Generates the next set into `set`: set 0 is the configuration's own
    /// loops; every later one continues the LCG streams and is entered where
    /// it joins the last set best.
    ///
    /// # Errors
    /// The axis whose loop could not be generated (a seed whose walk is
    /// degenerate); `set` is then neutral on that axis, and the stream has
    /// moved past those seeds, so the next call tries new ones.
    pub fn next_into<const CAP: usize>(
        &mut self,
        set: &mut LoopSet<N, CAP>,
    ) -> Result<SetInfo, AxisError> {
        if self.next == 0 {
            set.generate(&self.config)?;
            self.adopt(set);
            return Ok(SetInfo {
                number: 0,
                seeds: set.seeds,
                starts: set.starts(),
                mismatch: [0; 3],
                discarded: [0; 3],
            });
        }
        let mut config = self.config;
        config.pitch.seed = self.seeds[0];
        config.roll.seed = self.seeds[1];
        config.yaw.seed = self.seeds[2];
        set.seeds = self.seeds;
        set.number = self.next;
        let generated = set.loops.generate(&config);
        // Whatever happened, the next set starts past these seeds.
        self.seeds = set.seeds.map(|seed| after_loop(seed, N));
        self.next += 1;
        generated?;
        let mut mismatch = [0; 3];
        let mut discarded = [0; 3];
        for axis in Axis::ALL {
            let a = axis.index();
            let (drawn, cost) = self.draw(set, &mut config, axis);
            discarded[a] = drawn - 1;
            mismatch[a] = rms(cost, self.join_samples);
        }
        set.join_len = (self.join_samples + 2) as u8;
        self.capture(set);
        Ok(SetInfo {
            number: set.number,
            seeds: set.seeds,
            starts: set.starts(),
            mismatch,
            discarded,
        })
    }

    /// Draws the loop of `axis` into `set` until it keeps pace with the
    /// axis' last two loops and its join is within the bounds ([`Paces`]),
    /// each draw from where the last one's LCG stream stopped; after
    /// [`MAX_DRAWS`] the one closest to the bounds is kept (generated again
    /// from its seed). `set` holds the first draw, generated from
    /// `set.seeds`, and the stream's seeds are already past it. Returns the
    /// loops drawn and the kept entry's cost.
    fn draw<const CAP: usize>(
        &mut self,
        set: &mut LoopSet<N, CAP>,
        config: &mut HeadConfig,
        axis: Axis,
    ) -> (u8, u64) {
        let a = axis.index();
        let mut generated = true;
        let mut draws = 1;
        // (score, seed) of the closest loop drawn.
        let mut best = (u32::MAX, set.seeds[a]);
        loop {
            if generated {
                let (score, pace, turn, cost) = self.enter(set, axis, false);
                if Pace::within(score) {
                    self.pace[a].push(pace, turn);
                    return (draws, cost);
                }
                if score < best.0 {
                    best = (score, set.seeds[a]);
                }
            }
            if draws >= MAX_DRAWS {
                break;
            }
            let seed = self.seeds[a];
            self.seeds[a] = after_loop(seed, N);
            draws += 1;
            config.axis_mut(axis).seed = seed;
            set.seeds[a] = seed;
            // A degenerate walk counts as a discarded loop.
            generated = set.loops.generate_axis(config, axis).is_ok();
        }
        if !generated || set.seeds[a] != best.1 {
            config.axis_mut(axis).seed = best.1;
            set.seeds[a] = best.1;
            // Generated once already (if every draw was degenerate, the
            // axis stays neutral).
            let _ = set.loops.generate_axis(config, axis);
        }
        let (_, pace, turn, cost) = self.enter(set, axis, true);
        self.pace[a].push(pace, turn);
        (draws, cost)
    }

    /// Measures the loop of `axis` in `set` against the last two and, if
    /// it keeps pace (or `always`), enters it where it joins the exit best
    /// and blends the join. Returns its score ([`Paces::score`], then
    /// the larger of that and [`Paces::join_score`] once joined), its pace,
    /// its join's largest |d2| and its entry's cost (`u64::MAX`: not
    /// entered).
    fn enter<const CAP: usize>(
        &self,
        set: &mut LoopSet<N, CAP>,
        axis: Axis,
        always: bool,
    ) -> (u32, Pace, u16, u64) {
        let a = axis.index();
        let pace = Pace::of_loop(set.loops.axis(axis));
        let score = self.pace[a].score(pace);
        if !Pace::within(score) && !always {
            return (score, pace, 0, u64::MAX);
        }
        let j = self.join_samples;
        let (start, cost) = best_entry(set.loops.axis(axis), &self.exit[a], j);
        set.loops.set_start(axis, start);
        // The join: the outgoing exit blended into the entry.
        let t = set.loops.axis(axis);
        let (exit, join) = (&self.exit[a], &mut set.join[a]);
        for (m, (kept, out)) in join.iter_mut().zip(exit.iter()).take(j + 2).enumerate() {
            let out = i32::from(*out);
            // Between two samples of the axis' range: an i16 of m°.
            *kept = match m.checked_sub(1) {
                Some(i) => blend(out, t.angle(i).millidegrees(), join_weight(i, j)),
                None => out,
            } as i16;
        }
        // Its turns: playback −1..=J, then the loop's own J + 1 and J + 2.
        let after = [j + 1, j + 2].map(|i| t.angle(i).millidegrees());
        let samples = join.iter().take(j + 2).map(|&v| i32::from(v));
        let turn = max_turn(samples.chain(after));
        let score = score.max(self.pace[a].join_score(pace, turn));
        (score, pace, turn, cost)
    }

    /// Takes `set`, generated by [`LoopSet::generate`] from this stream's
    /// configuration, as the stream's first set (the boot set, generated
    /// and timed on its own): the next call of [`next_into`](Self::next_into)
    /// makes set 1.
    pub fn adopt<const CAP: usize>(&mut self, set: &LoopSet<N, CAP>) {
        self.seeds = set.seeds.map(|seed| after_loop(seed, N));
        self.next = set.number + 1;
        self.capture(set);
        for (axis, pace) in Axis::ALL.iter().zip(self.pace.iter_mut()) {
            *pace = Paces::new(Pace::of_loop(set.loops.axis(*axis)));
        }
    }

    /// Keeps the exit segment of `set`: the samples its join out plays,
    /// and the one before.
    fn capture<const CAP: usize>(&mut self, set: &LoopSet<N, CAP>) {
        let j = self.join_samples;
        for (axis, exit) in Axis::ALL.iter().zip(self.exit.iter_mut()) {
            let t = set.loops.axis(*axis);
            for (m, e) in exit.iter_mut().take(j + 2).enumerate() {
                // Playback index N − J − 1 + m (N: the entry again).
                // Inside the axis' range, which the configuration keeps
                // within ±32.767° (an i16 of m°).
                *e = t.angle(N - j - 1 + m).millidegrees() as i16;
            }
        }
    }
}

/// The LCG value r(N) after r(0) = `seed`: the last value a loop of `n`
/// samples draws (both closures draw r(1)..r(N)), and the next loop's seed.
/// By squaring the affine map r ↦ a·r + c (O(log n)).
#[must_use]
pub const fn after_loop(seed: u32, n: usize) -> u32 {
    // (mul, add): the map applied 2^k times.
    let (mut mul, mut add) = (LCG_A, LCG_C);
    let (mut acc_mul, mut acc_add) = (1u32, 0u32);
    let mut k = n;
    while k > 0 {
        if k & 1 == 1 {
            // acc ∘ (mul, add) first: r ↦ mul·(acc_mul·r + acc_add) + add.
            acc_mul = acc_mul.wrapping_mul(mul);
            acc_add = acc_add.wrapping_mul(mul).wrapping_add(add);
        }
        add = add.wrapping_mul(mul).wrapping_add(add);
        mul = mul.wrapping_mul(mul);
        k >>= 1;
    }
    seed.wrapping_mul(acc_mul).wrapping_add(acc_add)
}

/// The ring index where `incoming` joins `exit` best: the entry `s` that
/// minimises Σ (incoming(s + i) − exit(i + 1))² over i = 0, 3, 6, …, J, with
/// its cost (ties: the lowest index). Branch and bound: a candidate is
/// dropped as soon as its partial sum reaches the best so far, so most
/// cost one or two comparisons.
fn best_entry<const N: usize>(
    incoming: &Trajectory<Integral16, N>,
    exit: &[i16; KEPT],
    join: usize,
) -> (usize, u64) {
    // The loop in m°, once (1.8 KB of stack, far less than the engine's).
    let scale = incoming.scale();
    let mut angles = [0i16; N];
    for (a, s) in angles.iter_mut().zip(incoming.samples()) {
        *a = scale.angle(s.to_scratch()).millidegrees() as i16;
    }
    // The points compared, the join's middle and ends first: the bound
    // then cuts most candidates after one or two.
    let mut points = [0usize; MAX_JOIN_SAMPLES / MATCH_STRIDE + 1];
    let count = (join / MATCH_STRIDE + 1).min(points.len());
    for (k, p) in points.iter_mut().take(count).enumerate() {
        *p = k * MATCH_STRIDE;
    }
    let points = &mut points[..count];
    let middle = count / 2;
    points.swap(0, middle);
    points.swap(1, count - 1);
    let (mut best, mut best_cost) = (0, u64::MAX);
    for s in 0..N {
        let mut cost = 0u64;
        for &i in points.iter() {
            let k = s + i;
            let k = if k >= N { k - N } else { k };
            let value = i32::from(angles.get(k).copied().unwrap_or(0));
            let e = i32::from(exit.get(i + 1).copied().unwrap_or(0));
            let d = value.wrapping_sub(e).unsigned_abs().min(0xFFFF);
            cost += u64::from(d * d);
            if cost >= best_cost {
                break;
            }
        }
        if cost < best_cost {
            (best, best_cost) = (s, cost);
        }
    }
    (best, best_cost)
}

/// The RMS in m° of a [`best_entry`] cost.
fn rms(cost: u64, join: usize) -> u32 {
    let points = (join / MATCH_STRIDE + 1) as u64;
    let mean = cost / points;
    // Integer square root, rounded down (mean < 2³², root < 2¹⁶).
    let mut r = 0u64;
    let mut bit = 1u64 << 16;
    while bit > 0 {
        if (r + bit) * (r + bit) <= mean {
            r += bit;
        }
        bit >>= 1;
    }
    r as u32
}

/// A [`LoopSupply`](super::LoopSupply) that generates the next set when it
/// is taken, into the one buffer given back last: the stream played
/// without a generator task, for the host (traces, the firmware's expected
/// frames) and for tests. The frames are the firmware's as long as its
/// generator is never late.
#[derive(Debug)]
pub struct GenerateOnTake<H, const N: usize> {
    stream: LoopStream<N>,
    spare: Option<H>,
    /// Sets the stream could not generate.
    failures: u32,
}

impl<H, const N: usize, const CAP: usize> GenerateOnTake<H, N>
where
    H: core::ops::DerefMut<Target = LoopSet<N, CAP>>,
{
    /// Generates `stream`'s sets into `spare` (and then into each set given
    /// back).
    pub const fn new(stream: LoopStream<N>, spare: H) -> Self {
        Self {
            stream,
            spare: Some(spare),
            failures: 0,
        }
    }

    /// The generator.
    pub const fn stream(&self) -> &LoopStream<N> {
        &self.stream
    }

    /// Sets the stream could not generate.
    pub const fn failures(&self) -> u32 {
        self.failures
    }
}

impl<H, const N: usize, const CAP: usize> LoopSupply<H> for GenerateOnTake<H, N>
where
    H: core::ops::DerefMut<Target = LoopSet<N, CAP>>,
{
    fn take(&mut self) -> Option<H> {
        let mut set = self.spare.take()?;
        if self.stream.next_into(&mut set).is_ok() {
            Some(set)
        } else {
            self.failures = self.failures.saturating_add(1);
            self.spare = Some(set);
            None
        }
    }

    fn give_back(&mut self, set: H) {
        self.spare = Some(set);
    }
}
