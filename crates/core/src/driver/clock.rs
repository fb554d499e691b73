//! Frame deadline bookkeeping (pure: the caller supplies the time).

/// The frame period was zero ticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ZeroPeriod;

/// The frame to play now, from [`FrameClock::tick`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameTick {
    /// Frame index to play (for [`Playback::offsets`](crate::playback::Playback::offsets)).
    pub frame: u64,
    /// Frames skipped just before this one because it came late by whole periods.
    pub skipped: u64,
}

/// Deadlines of a fixed-rate frame loop, in the caller's clock ticks.
///
/// Wait until [`deadline`](Self::deadline), then call [`tick`](Self::tick) with
/// the current time. A frame written later than its *latch* after its
/// deadline (by default a whole period; on a board, the time until the PWM
/// wrap that takes its duty: [`with_latch`](Self::with_latch)) would go out
/// with the next frame's pulse, and the next frame's write, due before that
/// pulse, would overwrite it: so the clock skips to the first frame whose
/// pulse is still ahead. The missed frames are counted and their indices
/// jumped over (so playback stays in time), and the next deadline lies after
/// that frame's (so there is never a burst of catch-up frames, nor two writes
/// for one pulse). Deadlines advance by exact multiples of the period: no
/// drift.
///
/// ```
/// use idle_head_core::driver::{FrameClock, FrameTick};
/// let mut clock = FrameClock::new(20, 1000).unwrap();
/// assert_eq!(clock.tick(1000), FrameTick { frame: 0, skipped: 0 });
/// assert_eq!(clock.deadline(), 1020);
/// assert_eq!(clock.tick(1075), FrameTick { frame: 3, skipped: 2 }); // 55 ticks late
/// assert_eq!(clock.deadline(), 1080);
/// assert_eq!(clock.skipped_total(), 2);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameClock {
    period: u64,
    /// A frame written this long after its deadline still reaches its pulse.
    latch: u64,
    deadline: u64,
    next_frame: u64,
    skipped: u64,
}

impl FrameClock {
    /// A clock whose frame 0 is due at `start`, one frame every `period` ticks.
    ///
    /// # Errors
    /// [`ZeroPeriod`] if `period` is zero.
    pub const fn new(period: u64, start: u64) -> Result<Self, ZeroPeriod> {
        if period == 0 {
            return Err(ZeroPeriod);
        }
        Ok(Self {
            period,
            latch: period,
            deadline: start,
            next_frame: 0,
            skipped: 0,
        })
    }

    /// The same clock with a latch of `latch` ticks (at most a period): a
    /// frame written later than that after its deadline misses its pulse,
    /// and the clock plays the next one instead (see the type's docs).
    ///
    /// ```
    /// use idle_head_core::driver::{FrameClock, FrameTick};
    /// let mut clock = FrameClock::new(20, 1000).unwrap().with_latch(2);
    /// assert_eq!(clock.tick(1001), FrameTick { frame: 0, skipped: 0 });
    /// // 5 ticks late: too late for frame 1's pulse; frame 2 plays now.
    /// assert_eq!(clock.tick(1025), FrameTick { frame: 2, skipped: 1 });
    /// assert_eq!(clock.deadline(), 1060);
    /// ```
    #[must_use]
    pub const fn with_latch(mut self, latch: u64) -> Self {
        self.latch = if latch < self.period {
            latch
        } else {
            self.period
        };
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
        // late < (skipped + 1) · period, so the new deadline lies after `now`.
        let skipped = if late < self.latch {
            0
        } else {
            let past = late.saturating_add(self.period - self.latch);
            past.checked_div(self.period).unwrap_or(0)
        };
        let frame = self.next_frame.saturating_add(skipped);
        self.next_frame = frame.saturating_add(1);
        self.skipped = self.skipped.saturating_add(skipped);
        let advance = self.period.saturating_mul(skipped.saturating_add(1));
        self.deadline = self.deadline.saturating_add(advance);
        FrameTick { frame, skipped }
    }
}
