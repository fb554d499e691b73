//! The loop set buffers' round between the frame task and the loop
//! generator.
//!
//! Two `&'static mut` [`LoopSet`](idle_head_core::idle::LoopSet) buffers go
//! round through two one-slot channels, embassy-sync [`Signal`]s, free →
//! generator → ready → frame task → free, so the frame task never waits for
//! a set and never allocates (see `idle_head_core::idle`). (A `Signal`
//! rather than an embassy-sync `Channel`: the channel's state sits in a
//! `RefCell` whose borrow check would put a panic path on the frame path; a
//! signal's is a `Cell`.)

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::Instant;
use idle_head_core::console::ConsoleLink;
use idle_head_core::idle::{LoopStream, LoopSupply, SetInfo};
use idle_head_core::motion::{AxisError, DEFAULT_N};

use crate::config::SetRef;

/// What generating loop set 0 gave, for the boards' logs and checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FirstSet {
    /// Its checksum (the host computes the same).
    pub checksum: u32,
    /// Whether it was generated (else it holds the neutral pose).
    pub generated: bool,
    /// What it took, in the stopwatch's unit.
    pub precompute: u64,
}

/// The two one-slot channels the loop set buffers go round through: `free`
/// (a set the frame task no longer reads) and `ready` (a set generated,
/// waiting for its join). With two buffers, one plays while the other is
/// generated or waits: each slot holds at most one set, so none is ever
/// overwritten (a set signalled over another would be lost, never shared).
///
/// Loop set 0 goes from the generator to the frame task through a slot of
/// its own, `first`: the frame task waits for it before its first frame.
pub struct Exchange {
    first: Signal<CriticalSectionRawMutex, (SetRef, FirstSet)>,
    free: Signal<CriticalSectionRawMutex, SetRef>,
    ready: Signal<CriticalSectionRawMutex, SetRef>,
}

impl Exchange {
    /// Empty slots.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            first: Signal::new(),
            free: Signal::new(),
            ready: Signal::new(),
        }
    }

    /// Hands loop set 0, generated, to the frame task.
    pub fn start(&self, set: SetRef, info: FirstSet) {
        self.first.signal((set, info));
    }

    /// The frame task's wait for loop set 0.
    pub async fn first(&self) -> (SetRef, FirstSet) {
        self.first.wait().await
    }

    /// Hands `set` to the generator (at boot: the buffer not playing).
    pub fn give(&self, set: SetRef) {
        self.free.signal(set);
    }

    /// The frame task's end: takes ready sets, gives back played ones.
    #[must_use]
    pub const fn supply(&'static self) -> ExchangeSupply {
        ExchangeSupply { exchange: self }
    }

    /// The generator task's loop: waits for a free buffer, takes new seeds
    /// from `link` (the console's `seed`) if there are any, generates
    /// `stream`'s next set into it (the set after a reseed from the new
    /// seeds, joined in as any set is), reports it to `done` (with the time
    /// it took, in embassy ticks, preemption by higher-priority tasks
    /// included) and hands it to the frame task. A set that cannot be
    /// generated (a degenerate walk) is reported and generated again from
    /// the next seeds.
    pub async fn generate(
        &self,
        stream: &mut LoopStream<DEFAULT_N>,
        link: &ConsoleLink,
        mut done: impl FnMut(&Result<SetInfo, AxisError>, u64),
    ) -> ! {
        loop {
            let set = self.free.wait().await;
            if let Some(seeds) = link.take_seeds() {
                stream.reseed(seeds);
            }
            loop {
                let start = Instant::now();
                let result = stream.next_into(set);
                done(&result, start.elapsed().as_ticks());
                if result.is_ok() {
                    break;
                }
            }
            self.ready.signal(set);
        }
    }
}

impl Default for Exchange {
    fn default() -> Self {
        Self::new()
    }
}

/// The frame task's end of an [`Exchange`].
#[derive(Clone, Copy)]
pub struct ExchangeSupply {
    exchange: &'static Exchange,
}

impl LoopSupply<SetRef> for ExchangeSupply {
    fn take(&mut self) -> Option<SetRef> {
        self.exchange.ready.try_take()
    }

    fn give_back(&mut self, set: SetRef) {
        self.exchange.free.signal(set);
    }
}

#[cfg(test)]
mod tests;
