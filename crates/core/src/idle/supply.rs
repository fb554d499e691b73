//! Where the idle source gets its loop sets ([`LoopSupply`]): a leaf
//! module, implemented by the stream and the firmware's channels, used by
//! the source.

/// Where the frame task gets its next loop set and leaves the one it has
/// played: the firmware's one-slot channels to the generator task, or a
/// generator called on the spot (host).
pub trait LoopSupply<H> {
    /// The next set, if it is ready. Called once per join, on the frame
    /// where the join is due.
    fn take(&mut self) -> Option<H>;
    /// A set the frame task no longer reads, for the generator to fill.
    fn give_back(&mut self, set: H);
}

/// No supply: the fixed-loop mode, or a stream that never gets a set.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoSupply;

impl<H> LoopSupply<H> for NoSupply {
    fn take(&mut self) -> Option<H> {
        None
    }

    fn give_back(&mut self, set: H) {
        drop(set);
    }
}
