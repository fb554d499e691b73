//! The DMX receiver on a UART's characters: framing, start codes, slot
//! counts, errors and the counters, as the frame task and the console see
//! them through the link.

use idle_head_core::dmx::{Counters, Cue, DmxAddress, DmxLink, DmxSettings, UNIVERSE};

use super::{Receiver, Rx};

/// A frame as the UART delivers it after its break: start code `start`,
/// then `slots` slots, slot `n` (1-based) holding `n % 251`.
fn frame(start: u8, slots: usize) -> Vec<Rx> {
    let mut rx = vec![Rx::Byte(start)];
    rx.extend((1..=slots).map(|n| Rx::Byte((n % 251) as u8)));
    rx
}

/// The cue of a head at `address` in a frame made by [`frame`]: the
/// personality's slots by hand (yaw at address, pitch at +2, roll at +4,
/// 16 bit each; mix, trigger, intensity at +6, +7, +8).
fn expected(address: usize) -> Cue {
    let slot = |n: usize| (n % 251) as u16;
    let wide = |n: usize| slot(n) * 256 + slot(n + 1);
    Cue {
        pose: [wide(address + 2), wide(address + 4), wide(address)],
        mix: slot(address + 6) as u8,
        trigger: slot(address + 7) as u8,
        intensity: slot(address + 8) as u8,
    }
}

/// A link with DMX on at `address`.
fn link(address: u16) -> DmxLink {
    let link = DmxLink::new();
    link.set(DmxSettings {
        on: true,
        address: DmxAddress::new(address).unwrap(),
    });
    link
}

/// Feeds `rx` in order, flushing every `flush` characters (the FIFO
/// running empty) if given.
fn feed(receiver: &mut Receiver, link: &DmxLink, rx: &[Rx], flush: Option<usize>) {
    for (i, &c) in rx.iter().enumerate() {
        receiver.take(c, link);
        if flush.is_some_and(|n| (i + 1) % n == 0) {
            receiver.flush();
        }
    }
}

/// A receiver in step with the line: it has seen a break.
fn synced(link: &DmxLink) -> Receiver {
    let mut receiver = Receiver::new();
    receiver.take(Rx::Break, link);
    receiver
}

#[test]
fn a_good_frame_reaches_the_link_at_the_break_that_ends_it() {
    for flush in [None, Some(1), Some(7), Some(32)] {
        let link = link(1);
        let mut receiver = synced(&link);
        feed(&mut receiver, &link, &frame(0, 512), flush);
        assert_eq!(link.latest().1.seq, 0, "not before the break");
        receiver.take(Rx::Break, &link);
        let (on, latest) = link.latest();
        assert!(on);
        assert_eq!(latest.seq, 1);
        assert_eq!(latest.cue, expected(1), "flushed every {flush:?}");
        assert_eq!(
            link.counters(),
            Counters {
                good: 1,
                ..Counters::ZERO
            }
        );
    }
}

#[test]
fn the_bytes_before_the_first_break_are_no_frame() {
    let link = link(1);
    let mut receiver = Receiver::new();
    feed(&mut receiver, &link, &frame(0, 512)[100..], None);
    receiver.take(Rx::Break, &link);
    assert_eq!(link.latest().1.seq, 0);
    assert_eq!(link.counters(), Counters::ZERO);
}

#[test]
fn the_heads_slots_anywhere_in_the_universe() {
    for address in [1_u16, 2, 17, 100, 250, DmxAddress::LAST.get()] {
        let link = link(address);
        // (The address is taken at the break.)
        let mut receiver = synced(&link);
        feed(&mut receiver, &link, &frame(0, 512), None);
        receiver.take(Rx::Break, &link);
        assert_eq!(link.latest().1.cue, expected(usize::from(address)));
    }
}

#[test]
fn a_frame_ending_before_the_heads_slots_is_short() {
    let link = link(20);
    let mut receiver = synced(&link);
    // Slots 20..=28 are used: 27 slots end before the last.
    feed(&mut receiver, &link, &frame(0, 27), None);
    receiver.take(Rx::Break, &link);
    assert_eq!(link.latest().1.seq, 0);
    assert_eq!(link.counters().short, 1);
    // 28 slots are enough.
    feed(&mut receiver, &link, &frame(0, 28), None);
    receiver.take(Rx::Break, &link);
    assert_eq!(link.latest().1.seq, 1);
    assert_eq!(link.counters().good, 1);
}

#[test]
fn a_break_right_after_a_break_is_a_short_frame() {
    let link = link(1);
    let mut receiver = synced(&link);
    receiver.take(Rx::Break, &link);
    assert_eq!(link.counters().short, 1);
}

#[test]
fn a_frame_of_more_than_a_universe_is_long() {
    let link = link(1);
    let mut receiver = synced(&link);
    feed(
        &mut receiver,
        &link,
        &frame(0, usize::from(UNIVERSE) + 1),
        None,
    );
    receiver.take(Rx::Break, &link);
    assert_eq!(link.latest().1.seq, 0);
    assert_eq!(link.counters().long, 1);
}

#[test]
fn another_start_code_is_counted_and_skipped() {
    let link = link(1);
    let mut receiver = synced(&link);
    // An RDM packet (start code 0xCC) with bytes that would be a cue.
    feed(&mut receiver, &link, &frame(0xcc, 512), None);
    receiver.take(Rx::Break, &link);
    assert_eq!(link.latest().1.seq, 0);
    assert_eq!(link.counters().bad_start, 1);
}

#[test]
fn a_receive_error_garbles_the_frame_and_shows_at_once() {
    let link = link(1);
    let mut receiver = synced(&link);
    let rx = frame(0, 512);
    feed(&mut receiver, &link, &rx[..200], None);
    receiver.take(Rx::Error, &link);
    assert_eq!(link.counters().garbled, 1, "counted at the error");
    feed(&mut receiver, &link, &rx[200..], None);
    receiver.take(Rx::Break, &link);
    assert_eq!(link.latest().1.seq, 0, "no cue from a garbled frame");
    // The next frame is good again.
    feed(&mut receiver, &link, &rx, None);
    receiver.take(Rx::Break, &link);
    assert_eq!(link.latest().1.seq, 1);
    assert_eq!(
        link.counters(),
        Counters {
            good: 1,
            garbled: 1,
            ..Counters::ZERO
        }
    );
}

#[test]
fn a_new_address_takes_effect_with_the_frame_after_the_break() {
    let link = link(1);
    let mut receiver = synced(&link);
    let rx = frame(0, 512);
    feed(&mut receiver, &link, &rx[..50], None);
    // The console moves the head to address 40 mid-frame.
    link.set(DmxSettings {
        on: true,
        address: DmxAddress::new(40).unwrap(),
    });
    feed(&mut receiver, &link, &rx[50..], None);
    receiver.take(Rx::Break, &link);
    assert_eq!(link.latest().1.cue, expected(1), "this frame: the old one");
    feed(&mut receiver, &link, &rx, None);
    receiver.take(Rx::Break, &link);
    assert_eq!(link.latest().1.cue, expected(40), "the next: the new one");
    assert_eq!(link.counters().good, 2);
}

#[test]
fn every_frame_is_counted_once() {
    let link = link(1);
    let mut receiver = synced(&link);
    let mut good = 0;
    for n in 0..40_usize {
        match n % 4 {
            0 | 1 => {
                feed(&mut receiver, &link, &frame(0, 512), Some(8));
                good += 1;
            }
            2 => feed(&mut receiver, &link, &frame(0x17, 10), None),
            _ => feed(&mut receiver, &link, &frame(0, 3), None),
        }
        receiver.take(Rx::Break, &link);
    }
    let c = link.counters();
    assert_eq!((c.good, c.bad_start, c.short), (good, 10, 10));
    assert_eq!(link.latest().1.seq, good);
}
