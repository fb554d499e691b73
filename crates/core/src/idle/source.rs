//! The idle source the frame task plays: one loop set after another,
//! each entered through its join, or one set for ever.

use core::ops::Deref;

use crate::behaviour::IdleSource;
use crate::playback::Cursor;
use crate::units::{Angle, Microseconds, Timestamp};

use super::join::IdleTiming;
use super::stream::LoopSet;
use super::supply::LoopSupply;

/// Which idle motion the head plays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum IdleMode {
    /// A new loop set every loop, joined to the last: the head never repeats.
    #[default]
    NeverRepeating,
    /// The first set replayed for ever: the paper's fixed loop.
    FixedLoop,
}

/// What an [`IdlePlayer`] has done so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct IdleStats {
    /// Joins begun (sets taken over).
    pub joins: u32,
    /// Joins that found no set ready: the current set played once more.
    pub late: u32,
    /// The number of the set playing.
    pub set: u32,
}

/// Plays loop sets (`H` derefs to a [`LoopSet`]) frame by frame, on the
/// frames' times (µs): in
/// [`IdleMode::NeverRepeating`] each set is followed by the next from
/// `supply`, entered through its join; in [`IdleMode::FixedLoop`] the first
/// set plays for ever. See the [module docs](super).
#[derive(Clone, Debug)]
// The fields every frame reads first, at small offsets (cheaper to address
// on the Cortex-M0).
#[repr(C)]
pub struct IdlePlayer<H, S> {
    /// The time from which on [`on_event`](Self::on_event) plays the
    /// frames: every frame of a join, else the next join (`u64::MAX`: never).
    slow_from: u64,
    /// The time of `current`'s start (its local time 0).
    origin: u64,
    current: H,
    /// Whether `current` is still playing its join.
    joining: bool,
    /// The local time of the next event: the join's end (while `joining`),
    /// else the next join (`u64::MAX`: never).
    event: u64,
    cursor: Cursor,
    supply: S,
    timing: IdleTiming,
    /// [`IdleTiming::join_read_us`], worked out once (it divides in 64
    /// bits, which would otherwise cost the frame a join starts at some
    /// 300 instructions).
    join_read: u64,
    /// Where a set stands when the next one takes over (at `L − J`), as
    /// the cursor keeps it ([`Cursor::position_of`]): the new set's
    /// position is the cursor's less this, without a division.
    join_shift: (u32, u32),
    /// Whether sets follow each other.
    stream: bool,
    stats: IdleStats,
}

impl<H, S> IdlePlayer<H, S> {
    /// What the player has done so far.
    #[must_use]
    pub const fn stats(&self) -> IdleStats {
        self.stats
    }

    /// The timing of the loops.
    #[must_use]
    pub const fn timing(&self) -> &IdleTiming {
        &self.timing
    }

    /// Whether a join is under way.
    #[must_use]
    pub const fn in_join(&self) -> bool {
        self.joining
    }

    /// The set playing.
    #[must_use]
    pub const fn current(&self) -> &H {
        &self.current
    }
}

impl<H, S, const N: usize, const CAP: usize> IdlePlayer<H, S>
where
    H: Deref<Target = LoopSet<N, CAP>>,
    S: LoopSupply<H>,
{
    /// Plays `first` from time 0, then (in [`IdleMode::NeverRepeating`])
    /// the sets of `supply`.
    #[must_use]
    pub const fn new(first: H, supply: S, timing: IdleTiming, mode: IdleMode) -> Self {
        let stream = matches!(mode, IdleMode::NeverRepeating);
        let fresh = Cursor::new(timing.playback);
        let event = if stream { timing.period_us() } else { u64::MAX };
        Self {
            slow_from: event,
            origin: 0,
            current: first,
            joining: false,
            event,
            cursor: fresh,
            supply,
            timing,
            join_read: timing.join_read_us(),
            join_shift: fresh.position_of(timing.period_us()),
            stream,
            stats: IdleStats {
                joins: 0,
                late: 0,
                set: 0,
            },
        }
    }

    /// The idle offsets of the frame at `at`.
    #[inline]
    pub fn offsets(&mut self, at: Timestamp) -> [Angle; 3] {
        if at.0 >= self.slow_from {
            return self.slow(at);
        }
        self.cursor.offsets(at, &*self.current)
    }

    /// Frames come `period` apart after the last one played: the cursor
    /// takes the new step (between frames: the divisions happen here).
    pub const fn set_frame_period(&mut self, period: Microseconds) {
        self.timing.playback = self.timing.playback.with_frame_period(period);
        self.cursor.set_frame_period(period);
    }

    /// A frame of a join, or one at or past an event.
    #[inline(never)]
    fn slow(&mut self, at: Timestamp) -> [Angle; 3] {
        let local = at.0.wrapping_sub(self.origin);
        if local >= self.event {
            self.on_event(local);
        }
        // Every frame of a join comes here; after it, the next join.
        self.slow_from = if self.joining {
            at.0
        } else {
            self.origin.saturating_add(self.event)
        };
        if self.joining {
            return self.cursor.offsets(at, &self.current.views());
        }
        self.cursor.offsets(at, &*self.current)
    }

    /// A frame at or past an event: the end of a join (the set plays on
    /// alone), or a join due (the next set taken, its join begins).
    fn on_event(&mut self, local: u64) {
        if self.joining {
            // Its join played (and no spline window reaches back into it),
            // the set reads its own samples from now on: from the join's
            // last sample on they are the same.
            self.joining = false;
            self.event = self.timing.period_us();
            return;
        }
        if !self.stream {
            self.event = u64::MAX;
            return;
        }
        let Some(set) = self.supply.take() else {
            // Not ready: the current set is seamless and plays once more;
            // its join out falls on the same samples a loop later.
            self.stats.late = self.stats.late.saturating_add(1);
            self.event = self.event.saturating_add(self.timing.loop_us);
            return;
        };
        // The outgoing set's exit is in the new set's join: it is read no more.
        let outgoing = core::mem::replace(&mut self.current, set);
        self.supply.give_back(outgoing);
        self.origin = self.origin.wrapping_add(self.event);
        let local = local - self.event;
        // The new set from where the cursor stands (same loop length and
        // samples: the same steps), or, after a late frame, from its time.
        self.cursor.rebase(self.origin, self.join_shift);
        self.joining = true;
        self.event = self.join_read;
        self.stats.joins = self.stats.joins.saturating_add(1);
        self.stats.set = self.current.number();
        if local >= self.event {
            // Skipped past the whole join.
            self.on_event(local);
        }
    }
}

impl<H, S, const N: usize, const CAP: usize> IdleSource for IdlePlayer<H, S>
where
    H: Deref<Target = LoopSet<N, CAP>>,
    S: LoopSupply<H>,
{
    #[inline]
    fn offsets(&mut self, at: Timestamp) -> [Angle; 3] {
        IdlePlayer::offsets(self, at)
    }

    fn set_frame_period(&mut self, period: Microseconds) {
        IdlePlayer::set_frame_period(self, period);
    }
}
