//! The DMX512 receiver, board-neutral: what a board's UART receives (bytes,
//! breaks, receive errors, character by character as its FIFO holds them)
//! goes through the core's [`Decoder`], which keeps the head's slots, and
//! each good frame's cue goes to the frame task through the show link
//! (`dmx`, in [`Links`](crate::boot::Links)): a few bytes copied in a critical section,
//! which the frame task reads between two frames. The receiver never waits
//! for the frame task, nor the frame task for it.
//!
//! A board feeds [`RECEIVER`](crate::boot::RECEIVER) from its UART's receive interrupt
//! (`idle-head-rp`: UART1 on GP9, below the frame task's priority): no
//! task, no buffer, no DMA.

use idle_head_core::dmx::{Cue, Decoder, DmxAddress, DmxLink};

/// One character of a UART's receive FIFO, as the DMX receiver sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Rx {
    /// A byte received without error.
    Byte(u8),
    /// A break: the line held low for longer than a character (a frame
    /// begins).
    Break,
    /// A framing, parity or overrun error: bytes were lost or damaged.
    Error,
}

/// The receiver's state: the decoder, fed by the board's UART interrupt.
pub struct Receiver {
    decoder: Decoder,
    /// Bytes received since the last hand-over to the decoder.
    batch: [u8; BATCH],
    len: usize,
}

/// Bytes handed to the decoder at once.
const BATCH: usize = 16;

impl Receiver {
    /// Waiting for the first break, at address 1 (the link's address is
    /// taken at every frame's start).
    #[must_use]
    pub const fn new() -> Self {
        Self {
            decoder: Decoder::new(DmxAddress::FIRST),
            batch: [0; BATCH],
            len: 0,
        }
    }

    /// One character from the UART, in order; a good frame's cue goes to
    /// `link` at the break that ends it.
    pub fn take(&mut self, rx: Rx, link: &DmxLink) {
        match rx {
            Rx::Byte(byte) => {
                if let Some(slot) = self.batch.get_mut(self.len) {
                    *slot = byte;
                    self.len += 1;
                }
                if self.len == BATCH {
                    self.flush();
                }
            }
            Rx::Break => {
                self.flush();
                let cue = self.decoder.end_frame().map(|s| Cue::from_slots(&s));
                link.record(cue, self.decoder.counters());
                // A new address takes effect with the frame that begins.
                self.decoder.set_address(link.settings().address);
            }
            Rx::Error => {
                self.flush();
                self.decoder.error();
                link.record(None, self.decoder.counters());
            }
        }
    }

    /// Hands the bytes received so far to the decoder (the board calls it
    /// when its FIFO is empty, so that a frame's slots are decoded as they
    /// come).
    pub fn flush(&mut self) {
        self.decoder
            .push(self.batch.get(..self.len).unwrap_or_default());
        self.len = 0;
    }
}

impl Default for Receiver {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests;
