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
/// the current time. A frame late by one or more whole periods skips the missed
/// frames: their indices are counted and jumped over (so playback stays in time)
/// and the next deadline lies after `now` (so there is never a burst of
/// catch-up frames). Deadlines advance by exact multiples of the period: no
/// drift. The period may change between two frames
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
        // late < (skipped + 1) · period, so the new deadline lies after `now`
        // (divided only when late by a period or more).
        let skipped = if late < self.period {
            0
        } else {
            late.checked_div(self.period).unwrap_or(0)
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
        self.frame_us = frame.0;
        self.step_ms = frame.0 / 1000;
        self.step_sub = frame.0 % 1000;
    }
}
