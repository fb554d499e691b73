//! Frame-by-frame playback: the exact position kept with additions only,
//! and each loop's spline window reused until the position leaves it.
//!
//! The position is exact at every frame, kept with `u32` additions (a frame
//! that does not follow the last is located from its time, as
//! [`Playback::position_at`] does); samples are read ahead, so a frame that
//! moves on to the next segment reads none.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Playback”).

use super::timing::{LoopSource, Playback, T_BITS, Weights, Window, mul_div_rem, wrap};
use crate::units::{Angle, Microseconds, Timestamp};

/// Plays three loops frame by frame; the same offsets as
/// [`Playback::offsets`], see the [module docs](self).
///
/// ```
/// use idle_head_core::playback::{Playback, Player};
/// use idle_head_core::{Angle, Microseconds, Millis};
///
/// let ramp: [Angle; 4] = [0, 1000, 2000, 1000].map(Angle::from_millidegrees);
/// let playback = Playback::new(Millis(160), Microseconds(20_000), 4).unwrap();
/// let mut player = Player::new(playback, [&ramp, &ramp, &ramp]);
/// for frame in 0..20 {
///     assert_eq!(player.offsets(frame), playback.offsets(frame, [&ramp, &ramp, &ramp]));
/// }
/// assert_eq!(player.offsets(3)[0].millidegrees(), 1625); // a jump back: located exactly
/// ```
#[derive(Debug)]
pub struct Player<'a, L: ?Sized> {
    cursor: Cursor,
    loops: [&'a L; 3],
}

impl<L: ?Sized> Clone for Player<'_, L> {
    fn clone(&self) -> Self {
        Self {
            cursor: self.cursor,
            loops: self.loops,
        }
    }
}

impl<'a, L: LoopSource + ?Sized> Player<'a, L> {
    /// Playback of `loops` (`[pitch, roll, yaw]`) by `playback`, at frame 0.
    #[must_use]
    pub const fn new(playback: Playback, loops: [&'a L; 3]) -> Self {
        Self {
            cursor: Cursor::new(playback),
            loops,
        }
    }

    /// The playback parameters.
    #[must_use]
    pub const fn playback(&self) -> &Playback {
        self.cursor.playback()
    }

    /// The three offsets (pitch, roll, yaw) of frame `frame` (at `frame`
    /// frame periods): those of [`Playback::offsets`], cheapest when
    /// `frame` follows the last one.
    #[inline]
    pub fn offsets(&mut self, frame: u64) -> [Angle; 3] {
        let at = Timestamp::of_frame(frame, self.cursor.playback.frame_period());
        self.offsets_at(at)
    }

    /// The three offsets of the frame at `at`, cheapest when it comes one
    /// frame period after the last.
    #[inline]
    pub fn offsets_at(&mut self, at: Timestamp) -> [Angle; 3] {
        self.cursor.offsets(at, &self.loops)
    }

    /// Frames come `period` apart after the last one played (see
    /// [`Cursor::set_frame_period`]).
    pub const fn set_frame_period(&mut self, period: Microseconds) {
        self.cursor.set_frame_period(period);
    }
}

/// The state of a [`Player`] without its loops: the position and the
/// spline windows, for callers that hold the loops themselves (and change
/// them: a cursor must be given the same loops from one call to the next,
/// or be [`restart_at`](Self::restart_at) another time).
#[derive(Clone, Copy, Debug)]
pub struct Cursor {
    playback: Playback,
    /// The time played as the loops' time 0, µs.
    origin: u64,
    /// The time `pos` and `rem` belong to, µs.
    here: u64,
    /// `⌊X/L⌋`: the sample index (above 12 bits) and `t` (Q12).
    pos: u32,
    /// `(X mod L)/g`.
    rem: u32,
    /// `⌊S/L⌋`.
    step: u32,
    /// `(S mod L)/g`.
    step_rem: u32,
    /// `L/g`.
    den: u32,
    /// The windows around `pos`, `[pitch, roll, yaw]`.
    windows: [Window; 3],
    /// Samples read ahead in each window (0..=2).
    ahead: u8,
    /// Whether the sums fit `u32` (else every frame is [`Playback::offsets_at`]).
    incremental: bool,
    /// Whether `pos` and `rem` belong to `here`.
    positioned: bool,
    /// What `windows` hold.
    read: Read,
}

/// What a [`Cursor`]'s windows hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Read {
    /// The first sample of `pos`'s segment only (`pos` on it).
    Sample,
    /// The segment around `pos`.
    Segment,
    /// Other loops' samples (after [`Cursor::rebase`]): the next frame
    /// reads whole windows.
    Stale,
}

impl Cursor {
    /// A cursor for `playback`, at time 0, with nothing read yet.
    #[must_use]
    pub const fn new(playback: Playback) -> Self {
        let loop_us = playback.loop_us.get();
        let samples = playback.samples.get() as u64;
        // g = gcd(n·2¹², L): every X mod L is a multiple of it.
        let g = match (samples << T_BITS).checked_rem(loop_us) {
            Some(r) => gcd(r, loop_us),
            None => 1,
        };
        let den = match loop_us.checked_div(g) {
            Some(den) => den,
            None => 1,
        };
        let incremental = samples < 1 << 19 && den < 1 << 31;
        let mut cursor = Self {
            playback,
            origin: 0,
            here: 0,
            pos: 0,
            rem: 0,
            step: 0,
            step_rem: 0,
            den: if incremental { den as u32 } else { 1 },
            windows: [Window::EMPTY; 3],
            ahead: 0,
            incremental,
            positioned: false,
            read: Read::Sample,
        };
        cursor.set_frame_period(playback.frame_period());
        cursor
    }

    /// The position of time `at` (µs from the loops' start) as the cursor
    /// keeps it: `⌊X/L⌋` and `(X mod L)/g` (see the module docs; divides).
    #[must_use]
    pub const fn position_of(&self, at: u64) -> (u32, u32) {
        let (pos, rem) = self.playback.locate_at(at, T_BITS);
        let g = match self.playback.loop_us.get().checked_div(self.den as u64) {
            Some(g) => g,
            None => 1,
        };
        let rem = match rem.checked_div(g) {
            Some(r) => r,
            None => 0,
        };
        (pos as u32, rem as u32)
    }

    /// Plays other loops of the same playback from time `origin` on, where
    /// these loops stood at `shift` (a [`position_of`](Self::position_of)):
    /// the position goes on from where it is, less `shift`, and the next
    /// frame reads whole windows of the new loops; no division (a join
    /// lands between two frames at most rates). Not positioned yet, the
    /// next frame is located from its time.
    pub const fn rebase(&mut self, origin: u64, shift: (u32, u32)) {
        self.origin = origin;
        if !self.positioned || !self.incremental {
            return;
        }
        let wrap = (self.playback.samples.get() as u32) << T_BITS;
        // (pos, rem) − shift, borrowing from pos, modulo the loop.
        let (mut pos, mut rem) = (self.pos, self.rem);
        if rem < shift.1 {
            rem += self.den - shift.1;
            pos = if pos == 0 { wrap - 1 } else { pos - 1 };
        } else {
            rem -= shift.1;
        }
        let shift = if shift.0 >= wrap { 0 } else { shift.0 };
        pos = if pos >= shift {
            pos - shift
        } else {
            pos + wrap - shift
        };
        self.pos = pos;
        self.rem = rem;
        self.read = Read::Stale;
    }

    /// Frames come `period` apart from the last frame played on: the step
    /// `S` for it (its divisions happen here, not on the frame path). The
    /// position stays where it is.
    pub const fn set_frame_period(&mut self, period: Microseconds) {
        self.playback = self.playback.with_frame_period(period);
        let loop_us = self.playback.loop_us.get();
        let samples = self.playback.samples.get() as u64;
        // S = (F mod L)·n·2¹²: ⌊S/L⌋ and (S mod L)/g.
        let f = match (self.playback.frame_us as u64).checked_rem(loop_us) {
            Some(f) => f,
            None => 0,
        };
        let (step, s_rem) = mul_div_rem(f, samples << T_BITS, loop_us);
        let g = match loop_us.checked_div(self.den as u64) {
            Some(g) => g,
            None => 1,
        };
        let step_rem = match s_rem.checked_div(g) {
            Some(r) => r,
            None => 0,
        };
        if self.incremental {
            self.step = step as u32;
            self.step_rem = step_rem as u32;
        }
    }

    /// Forgets the position and the samples read and plays the time
    /// `origin` (µs) as the loops' time 0: the next call locates its frame
    /// from its time and reads whole windows.
    pub const fn restart_at(&mut self, origin: u64) {
        self.origin = origin;
        self.positioned = false;
    }

    /// The playback parameters.
    #[must_use]
    pub const fn playback(&self) -> &Playback {
        &self.playback
    }

    /// The three offsets (pitch, roll, yaw) of the frame at `at` of
    /// `loops`: those of [`Playback::offsets_at`] at `at − origin`,
    /// cheapest when `at` follows the last frame by the frame period.
    #[inline(never)]
    pub fn offsets<A: Axes + ?Sized>(&mut self, at: Timestamp, loops: &A) -> [Angle; 3] {
        let at = at.0;
        if !self.incremental {
            let local = Timestamp(at.wrapping_sub(self.origin));
            return self
                .playback
                .offsets_at(local, [loops.axis(0), loops.axis(1), loops.axis(2)]);
        }
        if self.positioned && at == self.here.wrapping_add(u64::from(self.playback.frame_us)) {
            let before = self.pos;
            self.advance();
            self.here = at;
            match self.read {
                Read::Segment => self.follow(before, loops),
                Read::Sample => self.complete(before, loops),
                Read::Stale => self.load((self.pos >> T_BITS) as usize, loops),
            }
        } else if at != self.here || !self.positioned || self.read == Read::Stale {
            self.seek(at, loops);
        }
        let t = self.pos & ((1 << T_BITS) - 1);
        // One set of weights for the three axes.
        let weights = Weights::at(t);
        let [pitch, roll, yaw] = &self.windows;
        [
            pitch.at_weights(&weights),
            roll.at_weights(&weights),
            yaw.at_weights(&weights),
        ]
        .map(Angle::from_millidegrees)
    }

    /// One frame on (see the module docs).
    #[inline]
    fn advance(&mut self) {
        // rem, step_rem < den < 2³¹; pos < n·2¹², step < n·2¹², n < 2¹⁹.
        self.rem += self.step_rem;
        self.pos += self.step;
        if self.rem >= self.den {
            self.rem -= self.den;
            self.pos += 1;
        }
        let wrap = (self.playback.samples.get() as u32) << T_BITS;
        if self.pos >= wrap {
            self.pos -= wrap;
        }
    }

    /// Goes to time `at` exactly, and reads its windows (only the sample
    /// it lies on, if it lies on one).
    #[inline(never)]
    fn seek<A: Axes + ?Sized>(&mut self, at: u64, loops: &A) {
        let (pos, rem) = match at.wrapping_sub(self.origin) {
            0 => (0, 0),
            local => self.playback.locate_at(local, T_BITS),
        };
        // pos < n·2¹² < 2³¹; the remainder in units of g = L/den is below den.
        self.pos = pos as u32;
        // (A remainder of 0, as at time 0, needs no 64-bit division.)
        self.rem = if rem == 0 {
            0
        } else {
            let g = self.playback.loop_us.get().checked_div(u64::from(self.den));
            rem.checked_div(g.unwrap_or(1)).unwrap_or(0) as u32
        };
        self.here = at;
        self.positioned = true;
        let index = (self.pos >> T_BITS) as usize;
        if self.pos & ((1 << T_BITS) - 1) == 0 {
            // The segment's value at t = 0 is its first sample, whatever the others.
            for (i, window) in self.windows.iter_mut().enumerate() {
                *window = Window::flat(loops.axis(i).angle(index).millidegrees());
            }
            self.ahead = 0;
            self.read = Read::Sample;
        } else {
            self.load(index, loops);
        }
    }

    /// Brings the windows from `before`'s sample to the position's.
    fn follow<A: Axes + ?Sized>(&mut self, before: u32, loops: &A) {
        let (index, from) = ((self.pos >> T_BITS) as usize, (before >> T_BITS) as usize);
        let n = self.playback.samples.get();
        if index == from {
            self.read_ahead(index, n, loops);
            return;
        }
        // Both below n.
        let passed = if index > from {
            index - from
        } else {
            index + n - from
        };
        if passed > 3 {
            self.load(index, loops);
            return;
        }
        // The samples entering: from + 3 ..= index + 2.
        for k in from + 3..=from + 2 + passed {
            if self.ahead > 0 {
                self.ahead -= 1;
                for window in &mut self.windows {
                    window.shift_ahead();
                }
            } else {
                let next = wrap(k, n);
                for (i, window) in self.windows.iter_mut().enumerate() {
                    window.shift(loops.axis(i).angle(next).millidegrees());
                }
            }
        }
    }

    /// Reads up to two samples past the windows of sample `index`.
    fn read_ahead<A: Axes + ?Sized>(&mut self, index: usize, n: usize, loops: &A) {
        while self.ahead < 2 {
            let next = wrap(index + 3 + usize::from(self.ahead), n);
            for (i, window) in self.windows.iter_mut().enumerate() {
                window.set_ahead(self.ahead, loops.axis(i).angle(next).millidegrees());
            }
            self.ahead += 1;
        }
    }

    /// Reads the rest of windows that hold only `before`'s sample: the three
    /// other samples if the position is still on its segment, else all four.
    fn complete<A: Axes + ?Sized>(&mut self, before: u32, loops: &A) {
        let index = (self.pos >> T_BITS) as usize;
        if index != (before >> T_BITS) as usize {
            self.load(index, loops);
            return;
        }
        let n = self.playback.samples.get();
        for (i, window) in self.windows.iter_mut().enumerate() {
            window.complete(loops.axis(i), n, index);
        }
        self.ahead = 0;
        self.read = Read::Segment;
    }

    /// Reads the windows around sample `index`.
    fn load<A: Axes + ?Sized>(&mut self, index: usize, loops: &A) {
        let n = self.playback.samples.get();
        for (i, window) in self.windows.iter_mut().enumerate() {
            *window = Window::load(loops.axis(i), n, index);
        }
        self.ahead = 0;
        self.read = Read::Segment;
    }
}

/// Three loops `[pitch, roll, yaw]` as a [`Cursor`] reads them.
pub trait Axes {
    /// The type of one axis' loop.
    type Loop: LoopSource + ?Sized;
    /// The loop of axis `index` (0, 1, 2; others read as the last).
    fn axis(&self, index: usize) -> &Self::Loop;
}

impl<L: LoopSource + ?Sized> Axes for [&L; 3] {
    type Loop = L;

    #[inline]
    fn axis(&self, index: usize) -> &L {
        match index {
            0 => self[0],
            1 => self[1],
            _ => self[2],
        }
    }
}

/// Greatest common divisor (`gcd(0, b) = b`).
const fn gcd(mut a: u64, mut b: u64) -> u64 {
    while let Some(r) = a.checked_rem(b) {
        a = b;
        b = r;
    }
    a
}
