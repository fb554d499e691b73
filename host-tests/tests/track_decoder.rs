//! The LD2450 decoder on damaged and random streams: every byte of a frame
//! corrupted in turn, and any bytes at all, never a panic, never a wrong
//! sighting, and the next good frame always found.

use idle_head_core::Millimetres;
use idle_head_core::track::ld2450::{Decoder, FRAME, Target, frame};
use idle_head_core::track::{Sighting, SightingSource};
use proptest::prelude::*;

fn good() -> [u8; FRAME] {
    let t = |x, y| {
        Some(Target {
            x: Millimetres(x),
            y: Millimetres(y),
            speed: 12,
            resolution: 320,
        })
    };
    frame(&[t(-782, 1713), None, t(1500, 4000)])
}

fn feed(d: &mut Decoder, bytes: &[u8]) -> Vec<Sighting> {
    let mut seen = Vec::new();
    d.feed(bytes, &mut |s| seen.push(s));
    seen
}

#[test]
fn every_byte_corrupted_in_turn() {
    let good = good();
    let expected = feed(&mut Decoder::new(), &good);
    assert_eq!(expected.len(), 1);
    for i in 0..FRAME {
        for flip in [0x01_u8, 0x80, 0xFF] {
            let mut bad = good;
            bad[i] ^= flip;
            let mut d = Decoder::new();
            let got = feed(&mut d, &bad);
            let frame_part = (4..FRAME - 2).contains(&i);
            if frame_part {
                // A payload byte: the frame is whole, its values differ.
                assert_eq!(got.len(), 1, "byte {i}");
            } else {
                // Header or footer: no sighting from the damaged frame.
                assert!(got.is_empty(), "byte {i} ^ {flip:#x}: {got:?}");
            }
            // The next good frame is found whatever came before.
            let next = feed(&mut d, &good);
            assert_eq!(next, expected, "after byte {i} ^ {flip:#x}");
        }
    }
}

proptest! {
    #[test]
    fn any_stream_then_a_good_frame(noise in proptest::collection::vec(any::<u8>(), 0..300)) {
        let good = good();
        let expected = feed(&mut Decoder::new(), &good);
        let mut d = Decoder::new();
        let before = d.counters();
        let _ = feed(&mut d, &noise);
        // A frame's worth of anything but a header byte ends whatever the
        // noise began; then the good frame decodes.
        let _ = feed(&mut d, &[0; FRAME]);
        let got = feed(&mut d, &good);
        prop_assert_eq!(got, expected);
        prop_assert!(d.counters().good > before.good);
    }

    #[test]
    fn random_bytes_in_any_pieces_never_panic(
        bytes in proptest::collection::vec(any::<u8>(), 0..600),
        cut in 0_usize..600,
    ) {
        let mut d = Decoder::new();
        let cut = cut.min(bytes.len());
        let _ = feed(&mut d, &bytes[..cut]);
        d.error();
        let _ = feed(&mut d, &bytes[cut..]);
        let c = d.counters();
        prop_assert!(c.good as usize * FRAME <= bytes.len());
    }
}
