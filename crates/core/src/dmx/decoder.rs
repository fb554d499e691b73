//! A universe's bytes in, the personality's slots out.

use super::{DmxAddress, FOOTPRINT, UNIVERSE, USED};

/// Frames seen since the receiver started, by what became of them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Counters {
    /// Frames used: start code 0, long enough, no error.
    pub good: u32,
    /// Frames that ended before the personality's last used slot.
    pub short: u32,
    /// Frames with more than 512 slots.
    pub long: u32,
    /// Frames with a start code other than 0 (RDM, text, …).
    pub bad_start: u32,
    /// Frames in which the UART reported a framing, parity or overrun error.
    pub garbled: u32,
}

impl Counters {
    /// Nothing counted yet.
    pub const ZERO: Self = Self {
        good: 0,
        short: 0,
        long: 0,
        bad_start: 0,
        garbled: 0,
    };
}

/// Where the decoder is in the stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum State {
    /// No break seen yet (or since an address change): the bytes belong to
    /// a frame whose start was missed.
    Unsynced,
    /// After a break: the next byte is the start code.
    Start,
    /// In a frame of start code 0, `slot` slots received.
    Slots,
    /// In a frame to skip (another start code, or garbled), counted.
    Skip,
}

/// The frame decoder: fed with what a UART receives (bytes, breaks and
/// receive errors), it keeps the slots of the personality at its address
/// and counts every frame.
///
/// ```
/// use idle_head_core::dmx::{Decoder, DmxAddress};
///
/// let mut dmx = Decoder::new(DmxAddress::new(3).unwrap());
/// dmx.push(&[9, 9, 9]); // the end of a frame whose start was missed
/// assert_eq!(dmx.end_frame(), None); // the break: in step from here on
/// let mut frame = [0_u8; 513]; // start code 0 and 512 slots
/// frame[3..13].copy_from_slice(&[1, 2, 3, 4, 5, 6, 7, 8, 9, 10]); // slots 3..=12
/// dmx.push(&frame[..100]);
/// dmx.push(&frame[100..]); // in any pieces
/// assert_eq!(dmx.end_frame(), Some([1, 2, 3, 4, 5, 6, 7, 8, 9, 10]));
/// dmx.push(&[0xcc, 1, 2]); // an RDM packet: counted, skipped
/// assert_eq!(dmx.end_frame(), None);
/// assert_eq!((dmx.counters().good, dmx.counters().bad_start), (1, 1));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Decoder {
    /// The personality's first slot, 0-based (so that a decoder at
    /// address 1 is all zero: a `static` of it takes no flash).
    first: u16,
    state: State,
    /// Slots received in this frame (saturating).
    slot: u16,
    /// The personality's slots of this frame, as far as received.
    slots: [u8; FOOTPRINT as usize],
    counters: Counters,
}

impl Decoder {
    /// A decoder for a head at `address`, waiting for the first break.
    #[must_use]
    pub const fn new(address: DmxAddress) -> Self {
        Self {
            first: address.get() - 1,
            state: State::Unsynced,
            slot: 0,
            slots: [0; FOOTPRINT as usize],
            counters: Counters::ZERO,
        }
    }

    /// The head's address from the next frame on: at once right after a
    /// break, else the frame in progress is dropped, uncounted.
    pub fn set_address(&mut self, address: DmxAddress) {
        if address.get() - 1 != self.first {
            self.first = address.get() - 1;
            if self.state != State::Start {
                self.state = State::Unsynced;
            }
        }
    }

    /// The address in use.
    #[must_use]
    pub const fn address(&self) -> DmxAddress {
        match DmxAddress::new(self.first + 1) {
            Some(a) => a,
            None => DmxAddress::FIRST,
        }
    }

    /// What became of the frames so far.
    #[must_use]
    pub const fn counters(&self) -> Counters {
        self.counters
    }

    /// Bytes received without error, in order; any number at a time.
    pub fn push(&mut self, bytes: &[u8]) {
        let mut rest = bytes;
        if self.state == State::Start {
            let Some((&code, tail)) = rest.split_first() else {
                return;
            };
            if code != 0 {
                self.counters.bad_start = self.counters.bad_start.saturating_add(1);
                self.state = State::Skip;
                return;
            }
            self.state = State::Slots;
            self.slot = 0;
            rest = tail;
        }
        if self.state != State::Slots {
            return;
        }
        // `rest` holds slots first..first + len (1-based); keep the ones
        // of the personality, address..address + FOOTPRINT.
        let first = usize::from(self.slot) + 1;
        let from = usize::from(self.first) + 1;
        let skip = from.saturating_sub(first);
        let at = first.saturating_sub(from);
        let src = rest.get(skip..).unwrap_or_default();
        let dst = self.slots.get_mut(at..).unwrap_or_default();
        for (d, s) in dst.iter_mut().zip(src) {
            *d = *s;
        }
        let total = usize::from(self.slot).saturating_add(rest.len());
        self.slot = u16::try_from(total).unwrap_or(u16::MAX);
    }

    /// The UART reported a framing, parity or overrun error: the frame in
    /// progress is garbled (counted), and skipped up to the next break.
    pub fn error(&mut self) {
        if matches!(self.state, State::Start | State::Slots) {
            self.counters.garbled = self.counters.garbled.saturating_add(1);
            self.state = State::Skip;
        }
    }

    /// A break: the frame in progress ends and a new one begins. The
    /// personality's slots if the frame that ended is a good one.
    pub fn end_frame(&mut self) -> Option<[u8; FOOTPRINT as usize]> {
        let state = self.state;
        self.state = State::Start;
        match state {
            State::Unsynced | State::Skip => None,
            // A break right after a break: a frame without even a start code.
            State::Start => {
                self.counters.short = self.counters.short.saturating_add(1);
                None
            }
            State::Slots if self.slot > UNIVERSE => {
                self.counters.long = self.counters.long.saturating_add(1);
                None
            }
            State::Slots if self.slot < self.first + USED => {
                self.counters.short = self.counters.short.saturating_add(1);
                None
            }
            State::Slots => {
                self.counters.good = self.counters.good.saturating_add(1);
                Some(self.slots)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(slots: usize, fill: impl Fn(usize) -> u8) -> Vec<u8> {
        let mut f = vec![0];
        f.extend((1..=slots).map(fill));
        f
    }

    fn synced(address: u16) -> Decoder {
        let mut d = Decoder::new(DmxAddress::new(address).unwrap());
        assert_eq!(d.end_frame(), None);
        d
    }

    #[test]
    fn keeps_the_slots_of_the_personality_wherever_the_pieces_split() {
        for address in [1, 2, 100, 503] {
            let bytes = frame(512, |s| (s % 251) as u8);
            let want: Vec<u8> = (0..10)
                .map(|i| ((address as usize + i) % 251) as u8)
                .collect();
            for cut in [1, 2, 7, 64, 300, 512] {
                let mut d = synced(address);
                for piece in bytes.chunks(cut) {
                    d.push(piece);
                }
                assert_eq!(
                    d.end_frame().unwrap().to_vec(),
                    want,
                    "address {address} cut {cut}"
                );
            }
        }
    }

    #[test]
    fn counts_short_long_bad_start_and_garbled_frames() {
        let mut d = synced(10);
        // Slot 18 is the personality's ninth: a frame of 17 slots is short,
        // of 18 good (slot 10 is reserved), of 513 long.
        d.push(&frame(17, |_| 1));
        assert_eq!(d.end_frame(), None);
        d.push(&frame(18, |_| 1));
        assert!(d.end_frame().is_some());
        d.push(&frame(513, |_| 1));
        assert_eq!(d.end_frame(), None);
        d.push(&[0x17, 1, 2, 3]);
        assert_eq!(d.end_frame(), None);
        d.push(&frame(40, |_| 1));
        d.error();
        d.push(&[1, 2, 3]);
        assert_eq!(d.end_frame(), None);
        // Two breaks in a row: a frame without a start code.
        assert_eq!(d.end_frame(), None);
        assert_eq!(
            d.counters(),
            Counters {
                good: 1,
                short: 2,
                long: 1,
                bad_start: 1,
                garbled: 1
            }
        );
        // Bytes and errors before the first break count for nothing.
        let mut fresh = Decoder::new(DmxAddress::FIRST);
        fresh.push(&[0, 1, 2]);
        fresh.error();
        assert_eq!(fresh.end_frame(), None);
        assert_eq!(fresh.counters(), Counters::default());
    }

    #[test]
    fn an_address_change_waits_for_the_next_break() {
        let mut d = synced(1);
        d.push(&frame(20, |s| s as u8));
        d.set_address(DmxAddress::new(5).unwrap());
        assert_eq!(d.end_frame(), None);
        d.push(&frame(20, |s| s as u8));
        assert_eq!(d.end_frame(), Some([5, 6, 7, 8, 9, 10, 11, 12, 13, 14]));
        assert_eq!(d.counters().good, 1);
        assert_eq!(d.address().get(), 5);
        // Right after a break, the next frame is read at the new address.
        d.set_address(DmxAddress::new(2).unwrap());
        d.push(&frame(20, |s| s as u8));
        assert_eq!(d.end_frame(), Some([2, 3, 4, 5, 6, 7, 8, 9, 10, 11]));
    }
}
