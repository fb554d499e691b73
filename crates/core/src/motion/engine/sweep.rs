//! The seamless closure's circular sweep: the window slides around the loop
//! over a ring of W taps, and the quantised integral X is stored.
//!
//! The wrap correction E, summed in wrapping `i32`, stays below 2²⁴ for
//! every window and loop length (`host-tests/tests/wrap_correction.rs`
//! checks it), so the sweep is exact.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “The seamless sweep”).

use crate::motion::lcg::Lcg;
use crate::motion::storage::Sample;

/// The taps of the sliding window: at most the kernel's capacity `CAP`
/// ≤ [`MAX_WINDOW`](crate::motion::MAX_WINDOW) on the stack (16 bytes each), without clearing all of
/// them per axis.
pub(super) type Ring<const CAP: usize> = heapless::Vec<Tap, CAP>;

/// One tap of the sliding window: the kernel table entry of its residue j
/// and the step currently in the window at that residue. The step leaving
/// the window and the one entering it share the residue, so this ring
/// replaces a second, lagging generator.
#[derive(Clone, Copy)]
pub(super) struct Tap {
    /// Q·cos, Q·sin of the table entry, as words (16-byte taps): 36,160
    /// instructions fewer for the default set than `i16` in 12-byte taps.
    c: i32,
    s: i32,
    /// The step in the window at this residue: −1 up, 0 down.
    up: i32,
    /// Scratch: the velocity V − q of the tap's latest sample.
    v: i32,
}

impl Tap {
    /// No table entry, no step.
    const EMPTY: Self = Self {
        c: 0,
        s: 0,
        up: 0,
        v: 0,
    };
}

/// The initial window's sums (outputs n = W−1, steps k = 0..W−1).
pub(super) struct Window {
    /// The phasor sums Pb꜀, Pbₛ of its up-steps.
    pub(super) pc: i32,
    pub(super) ps: i32,
    /// Q²·Bb: its up-steps times Q².
    pub(super) bb: i32,
    /// The wrap correction E (see the module docs).
    pub(super) wrap: i32,
}

/// The state of the circular sweep (pass 2): the sliding sums, the
/// quantiser and X with its extremes, tracked only where its slope changes
/// sign (a few times per smoothing length).
pub(super) struct Sweep {
    pc: i32,
    ps: i32,
    /// Q²·Bb − q: the window's up-steps times Q², less the detrend.
    acc: i32,
    /// The quantiser's residue: the integral of V − q modulo 2^shift.
    residue: i32,
    /// X after the last sample.
    x: i32,
    /// Whether ΔX of the last sample was ≥ 0.
    rising: bool,
    lo: i32,
    hi: i32,
}

impl Sweep {
    /// Starts at the first output, n = W−1: the initial `window` less the
    /// detrend `q`, quantised by 2^`shift` into `first` (table entry `last`,
    /// residue W−1).
    pub(super) fn start<S: Sample>(
        window: &Window,
        q: i32,
        (tc, ts): (i16, i16),
        shift: u32,
        first: &mut S,
    ) -> Self {
        let acc = window.bb - q;
        let v = acc - (i32::from(tc) * window.pc + i32::from(ts) * window.ps);
        let x = v >> shift;
        *first = S::from_scratch(x as i16);
        Self {
            pc: window.pc,
            ps: window.ps,
            acc,
            residue: v - (x << shift),
            x,
            rising: x >= 0,
            lo: x,
            hi: x,
        }
    }

    /// Slides over `out.len()` samples, the first at residue `j`, with the
    /// entering steps drawn from `walk`, and stores X.
    pub(super) fn run<S: Sample>(
        &mut self,
        out: &mut [S],
        taps: &mut [Tap],
        mut j: usize,
        walk: &mut Lcg,
        qq: i32,
        shift: u32,
    ) {
        let mut rest = out;
        while !rest.is_empty() {
            let ring = taps.get_mut(j..).unwrap_or_default();
            let take = ring.len().min(rest.len());
            let (now, later) = rest.split_at_mut(take);
            let ring = ring.get_mut(..take).unwrap_or_default();
            self.stretch(now, ring, walk, qq, shift);
            rest = later;
            j = 0;
        }
    }

    /// Slides the window over one stretch of taps, then stores its samples.
    fn stretch<S: Sample>(
        &mut self,
        now: &mut [S],
        ring: &mut [Tap],
        walk: &mut Lcg,
        qq: i32,
        shift: u32,
    ) {
        self.slide(ring, walk, qq);
        // The steps `raw_shift` picks for typical loops as constants:
        // 11,360 instructions fewer for the default set.
        match shift {
            17 => self.store::<S, 17>(now, ring, shift),
            18 => self.store::<S, 18>(now, ring, shift),
            19 => self.store::<S, 19>(now, ring, shift),
            _ => self.store::<S, 0>(now, ring, shift),
        }
    }

    /// The lowest and the highest X of the whole sweep.
    pub(super) fn extent(&self) -> (i32, i32) {
        (self.lo.min(self.x), self.hi.max(self.x))
    }

    /// X after the last sample.
    pub(super) fn x(&self) -> i32 {
        self.x
    }

    /// Slides the window over `ring`, leaving each sample's V − q in its tap.
    #[inline(never)] // 4,640 instructions fewer for the default set
    fn slide(&mut self, ring: &mut [Tap], walk: &mut Lcg, qq: i32) {
        let (mut pc, mut ps, mut acc) = (self.pc, self.ps, self.acc);
        let mut lcg = *walk;
        let mut one = |tap: &mut Tap| {
            let enter = lcg.next_value() as i32 >> 31;
            let (tc, ts) = (tap.c, tap.s);
            if enter != tap.up {
                tap.up = enter;
                if enter != 0 {
                    // An up-step enters, a down-step leaves.
                    pc += tc;
                    ps += ts;
                    acc += qq;
                } else {
                    pc -= tc;
                    ps -= ts;
                    acc -= qq;
                }
            }
            tap.v = acc - (tc * pc + ts * ps);
        };
        // Four taps a turn: 5,200 instructions fewer for the default set.
        let mut fours = ring.chunks_exact_mut(4);
        for four in &mut fours {
            if let [a, b, c, d] = four {
                one(a);
                one(b);
                one(c);
                one(d);
            }
        }
        for tap in fours.into_remainder() {
            one(tap);
        }
        (self.pc, self.ps, self.acc) = (pc, ps, acc);
        *walk = lcg;
    }

    /// Quantises the velocities in `ring` by 2^shift with error feedback
    /// (as [`Quantiser`](super::Quantiser)), advances X and stores it in
    /// `out`. Two loops, one while X rises and
    /// one while it falls, each noting the extreme where it ends: 18,960
    /// instructions fewer for the default set than one loop that tests the
    /// slope.
    ///
    /// The step is `2^SHIFT`, a constant, or `2^shift` with `SHIFT = 0`
    /// (`raw_shift` is at least 15, so 0 never is a step).
    #[inline(never)] // 2,400 instructions fewer for the default set
    fn store<S: Sample, const SHIFT: u32>(&mut self, out: &mut [S], ring: &[Tap], shift: u32) {
        let shift = if SHIFT == 0 { shift } else { SHIFT };
        // The residue (the sum so far mod 2^shift) rides in the top bits of
        // `low`: 5,600 instructions fewer for the default set than a masked
        // residue.
        let up = 32 - shift;
        let (mut low, mut x) = ((self.residue as u32) << up, self.x);
        let mut rising = self.rising;
        let len = out.len().min(ring.len());
        let (out, ring) = (&mut out[..len], &ring[..len]);
        let mut i = 0;
        while i < len {
            if rising {
                while i < len {
                    let v = ring[i].v + (low >> up) as i32;
                    low = (v as u32) << up;
                    let v = v >> shift;
                    if v < 0 {
                        // X (before this sample) is a local maximum.
                        self.hi = self.hi.max(x);
                        x += v;
                        out[i] = S::from_scratch(x as i16);
                        i += 1;
                        rising = false;
                        break;
                    }
                    x += v;
                    out[i] = S::from_scratch(x as i16);
                    i += 1;
                }
            } else {
                while i < len {
                    let v = ring[i].v + (low >> up) as i32;
                    low = (v as u32) << up;
                    let v = v >> shift;
                    if v >= 0 {
                        // X (before this sample) is a local minimum.
                        self.lo = self.lo.min(x);
                        x += v;
                        out[i] = S::from_scratch(x as i16);
                        i += 1;
                        rising = true;
                        break;
                    }
                    x += v;
                    out[i] = S::from_scratch(x as i16);
                    i += 1;
                }
            }
        }
        let residue = (low >> up) as i32;
        (self.residue, self.x, self.rising) = (residue, x, rising);
    }
}

/// Fills the tap ring with the initial window (steps k = 0..W−1, drawn from
/// `walk`) and returns its sums and the wrap correction E (see the module
/// docs); `n_mod_w` is N mod W.
#[inline(never)] // 1,120 instructions fewer for the default set
pub(super) fn initial_window<const CAP: usize>(
    table: &[(i16, i16)],
    n_mod_w: usize,
    walk: &mut Lcg,
    qq: i32,
    ring: &mut Ring<CAP>,
) -> Window {
    let w = table.len();
    // The window's steps, one tap each. Cannot fail: the table comes from a
    // kernel of the same capacity.
    let _ = ring.resize(w, Tap::EMPTY);
    let mut lcg = *walk;
    for (tap, &(c, s)) in ring.iter_mut().zip(table) {
        (tap.c, tap.s) = (i32::from(c), i32::from(s));
        tap.up = lcg.next_value() as i32 >> 31;
    }
    *walk = lcg;
    // The window's sums and E's early copies at phases k (SA), in one walk.
    let (last, early) = ring.split_last().unwrap_or((&Tap::EMPTY, &[]));
    let (mut pc, mut ps, mut ups) = (0i32, 0i32, 0i32);
    let (mut sc, mut ss) = (last.c, last.s);
    let mut sum = 0i32;
    for tap in early {
        let (c, s) = (tap.c, tap.s);
        if tap.up != 0 {
            pc += c;
            ps += s;
            ups += 1;
            sum = sum.wrapping_add((c * sc).wrapping_add(s * ss));
        }
        sc += c;
        ss += s;
    }
    if last.up != 0 {
        (pc, ps, ups) = (pc + last.c, ps + last.s, ups + 1);
    }
    // The late copies at phases (k + N) mod W (SB, sign folded in): the
    // table from N mod W on, then from 0.
    let (late_b, late_a) = table.split_at(n_mod_w);
    // Phase (N + W − 1) mod W = (N mod W) − 1, or W − 1 where N mod W = 0.
    let (c, s) = table
        .get(n_mod_w.checked_sub(1).unwrap_or(w - 1))
        .copied()
        .unwrap_or_default();
    let (early_a, early_b) = early.split_at(late_a.len().min(early.len()));
    let mut state = (-i32::from(c), -i32::from(s), sum);
    state = wrap_part(early_a, late_a, state);
    state = wrap_part(early_b, late_b, state);
    Window {
        pc,
        ps,
        bb: ups * qq,
        wrap: state.2,
    }
}

/// Adds to E's sum (`.2`, wrapping) the terms T(k)·S(k) of the up-steps
/// among `taps`, T(k) the k-th entry of `phases`, with the running sum S
/// (`.0`, `.1`) moving by −T(k) after each step (SB of the derivation, sign
/// folded in).
fn wrap_part(
    taps: &[Tap],
    phases: &[(i16, i16)],
    (mut sc, mut ss, mut sum): (i32, i32, i32),
) -> (i32, i32, i32) {
    for (tap, &(c, s)) in taps.iter().zip(phases) {
        let (c, s) = (i32::from(c), i32::from(s));
        if tap.up != 0 {
            sum = sum.wrapping_add((c * sc).wrapping_add(s * ss));
        }
        sc -= c;
        ss -= s;
    }
    (sc, ss, sum)
}
