//! Frame deadline bookkeeping (pure: the caller supplies the time).

use crate::units::{Microseconds, Timestamp};

/// The frame period was zero ticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ZeroPeriod;

/// The frame to play now, from [`FrameClock::tick`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameTick {
    /// Frame index to play.
    pub frame: u64,
    /// Frames skipped just before this one because it came late by whole periods.
    pub skipped: u64,
    /// The frame's time: the sum of the frame periods before it, µs (what
    /// the frame engine plays, [`Head::frame`](crate::behaviour::Head::frame)).
    pub at: Timestamp,
    /// The same in whole ms, wrapping (Bottango's curves are timed on it).
    pub ms: u32,
}

/// Deadlines of a frame loop, in the caller's clock ticks, and the frames'
/// own time in µs.
///
/// Wait until [`deadline`](Self::deadline), then call [`tick`](Self::tick) with
/// the current time. A frame written later than its *latch* after its
/// deadline (by default a whole period; on a board, the time until the PWM
/// wrap that takes its duty: [`with_latch_divisor`](Self::with_latch_divisor))
/// would go out with the next frame's pulse, and the next frame's write, due
/// before that pulse, would overwrite it: so the clock skips to the first
/// frame whose pulse is still ahead. The missed frames are counted and their
/// indices jumped over (so playback stays in time), and the next deadline
/// lies after that frame's (so there is never a burst of catch-up frames, nor
/// two writes for one pulse). Deadlines advance by exact multiples of the
/// period: no drift. The period may change between two frames
/// ([`set_period`](Self::set_period)): from the next frame on.
///
/// ```
/// use idle_head_core::driver::{FrameClock, FrameTick};
/// use idle_head_core::{Microseconds, Timestamp};
/// let mut clock = FrameClock::new(20, 1000, Microseconds(20_000)).unwrap();
/// assert_eq!(clock.tick(1000).frame, 0);
/// assert_eq!(clock.deadline(), 1020);
/// let late = clock.tick(1075); // 55 ticks late
/// assert_eq!((late.frame, late.skipped, late.at), (3, 2, Timestamp(60_000)));
/// assert_eq!(clock.deadline(), 1080);
/// assert_eq!(clock.skipped_total(), 2);
/// clock.set_period(5, Microseconds(5_000)); // from the next frame on
/// assert_eq!(clock.deadline(), 1065);
/// assert_eq!(clock.tick(1065).at, Timestamp(65_000));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameClock {
    period: u64,
    /// A frame written within a period over this after its deadline still
    /// reaches its pulse (1: a whole period), and that time in ticks.
    latch_divisor: u64,
    latch: u64,
    deadline: u64,
    next_frame: u64,
    skipped: u64,
    /// The frame period in µs, and in whole ms and the µs beyond them.
    frame_us: u32,
    step_ms: u32,
    step_sub: u32,
    /// The next frame's time: µs, and whole ms (wrapping) and the µs beyond.
    next_at: u64,
    next_ms: u32,
    next_sub: u32,
}

impl FrameClock {
    /// A clock whose frame 0 is due at `start`, one frame every `period`
    /// ticks, the frames `frame` apart in their own time.
    ///
    /// # Errors
    /// [`ZeroPeriod`] if `period` is zero.
    pub const fn new(period: u64, start: u64, frame: Microseconds) -> Result<Self, ZeroPeriod> {
        if period == 0 {
            return Err(ZeroPeriod);
        }
        Ok(Self {
            period,
            latch_divisor: 1,
            latch: period,
            deadline: start,
            next_frame: 0,
            skipped: 0,
            frame_us: frame.0,
            step_ms: frame.0 / 1000,
            step_sub: frame.0 % 1000,
            next_at: 0,
            next_ms: 0,
            next_sub: 0,
        })
    }

    /// The same clock with a latch of a period over `divisor` (at least 1):
    /// a frame written later than that after its deadline misses its pulse,
    /// and the clock plays the next one instead (see the type's docs).
    ///
    /// ```
    /// use idle_head_core::driver::FrameClock;
    /// use idle_head_core::Microseconds;
    /// let mut clock = FrameClock::new(20, 1000, Microseconds(20_000)).unwrap().with_latch_divisor(10);
    /// assert_eq!(clock.tick(1001).frame, 0);
    /// // 5 ticks late: too late for frame 1's pulse; frame 2 plays now.
    /// let late = clock.tick(1025);
    /// assert_eq!((late.frame, late.skipped), (2, 1));
    /// assert_eq!(clock.deadline(), 1060);
    /// ```
    #[must_use]
    pub const fn with_latch_divisor(mut self, divisor: u64) -> Self {
        self.latch_divisor = if divisor == 0 { 1 } else { divisor };
        self.latch = self.period / self.latch_divisor;
        self
    }

    /// When the next frame is due.
    #[must_use]
    pub const fn deadline(&self) -> u64 {
        self.deadline
    }

    /// The frame period in ticks.
    #[must_use]
    pub const fn period(&self) -> u64 {
        self.period
    }

    /// The frame period in the frames' time.
    #[must_use]
    pub const fn frame_period(&self) -> Microseconds {
        Microseconds(self.frame_us)
    }

    /// Frames skipped so far because they were late.
    #[must_use]
    pub const fn skipped_total(&self) -> u64 {
        self.skipped
    }

    /// The frame to play at time `now` (normally just after the deadline).
    ///
    /// Called early (before the deadline), it plays the due frame anyway.
    pub fn tick(&mut self, now: u64) -> FrameTick {
        let late = now.saturating_sub(self.deadline);
        // The frames whose latch has passed: a frame `k` periods on is
        // still in time while late < k · period + latch. (With the latch a
        // whole period: the frames a whole period late or more.) Then
        // late < (skipped + 1) · period, so the new deadline lies after
        // `now`. Divided only when late by a latch or more.
        let skipped = if late < self.latch {
            0
        } else {
            let past = late.saturating_add(self.period - self.latch);
            past.checked_div(self.period).unwrap_or(0)
        };
        if skipped > 0 {
            self.skip(skipped);
        }
        let tick = FrameTick {
            frame: self.next_frame,
            skipped,
            at: Timestamp(self.next_at),
            ms: self.next_ms,
        };
        self.next_frame = self.next_frame.saturating_add(1);
        self.deadline = self.deadline.saturating_add(self.period);
        self.next_at = self.next_at.saturating_add(u64::from(self.frame_us));
        self.next_sub += self.step_sub;
        self.next_ms = self.next_ms.wrapping_add(self.step_ms);
        if self.next_sub >= 1000 {
            self.next_sub -= 1000;
            self.next_ms = self.next_ms.wrapping_add(1);
        }
        tick
    }

    /// Jumps over `frames` frames that came too late.
    #[inline(never)]
    fn skip(&mut self, frames: u64) {
        self.next_frame = self.next_frame.saturating_add(frames);
        self.skipped = self.skipped.saturating_add(frames);
        self.deadline = self
            .deadline
            .saturating_add(self.period.saturating_mul(frames));
        let us = frames.saturating_mul(u64::from(self.frame_us));
        self.next_at = self.next_at.saturating_add(us);
        let us = us.saturating_add(u64::from(self.next_sub));
        self.next_ms = self.next_ms.wrapping_add((us / 1000) as u32);
        self.next_sub = (us % 1000) as u32;
    }

    /// From the next frame on (the one after the last [`tick`](Self::tick)),
    /// frames are `period` ticks apart, `frame` apart in their own time:
    /// that frame comes `period` after the last one.
    pub fn set_period(&mut self, period: u64, frame: Microseconds) {
        if period == 0 {
            return;
        }
        if self.next_frame > 0 {
            // Back to the last frame, then on by the new period.
            self.deadline = self
                .deadline
                .saturating_sub(self.period)
                .saturating_add(period);
            self.next_at = self
                .next_at
                .saturating_sub(u64::from(self.frame_us))
                .saturating_add(u64::from(frame.0));
            let (ms, sub) = (self.next_ms, self.next_sub);
            let (ms, sub) = if sub < self.step_sub {
                (
                    ms.wrapping_sub(self.step_ms + 1),
                    sub + 1000 - self.step_sub,
                )
            } else {
                (ms.wrapping_sub(self.step_ms), sub - self.step_sub)
            };
            let sub = sub + frame.0 % 1000;
            let ms = ms.wrapping_add(frame.0 / 1000);
            (self.next_ms, self.next_sub) = if sub >= 1000 {
                (ms.wrapping_add(1), sub - 1000)
            } else {
                (ms, sub)
            };
        }
        self.period = period;
        // The divisor is never 0 (`with_latch_divisor`); said again for
        // the frame path's proof.
        self.latch = period.checked_div(self.latch_divisor).unwrap_or(period);
        self.frame_us = frame.0;
        self.step_ms = frame.0 / 1000;
        self.step_sub = frame.0 % 1000;
    }
}
