//! A crowd of heads: the seeds of `seed board` come from each board's
//! unique id, so two boards flashed from one image move differently, and
//! the derivation gives seeds the motion accepts.

use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadConfig, HeadTrajectories, Integral16};
use idle_head_core::seed::{BoardId, PAPER};
use idle_head_core::settings::Settings;
use idle_head_core::{Angle, Axis};

/// The idle loops of `seeds`, as the board generates its first set.
fn loops(seeds: [u32; 3]) -> Box<HeadTrajectories<Integral16, DEFAULT_N>> {
    let mut config: HeadConfig = DEFAULT_HEAD;
    config.pitch.seed = seeds[0];
    config.roll.seed = seeds[1];
    config.yaw.seed = seeds[2];
    let mut head = Box::new(HeadTrajectories::new());
    head.generate(&config)
        .unwrap_or_else(|e| panic!("seeds {seeds:?}: {e:?}"));
    head
}

#[test]
fn two_boards_with_different_ids_move_differently() {
    let settings = Settings::DEFAULT;
    let a = settings.idle_seeds(BoardId(0xE660_5838_1B23_4A2F));
    let b = settings.idle_seeds(BoardId(0xE660_5838_1B23_4A30));
    assert_ne!(a, b);
    let (la, lb) = (loops(a), loops(b));
    for axis in Axis::ALL {
        let diff: Vec<i32> = (0..DEFAULT_N)
            .map(|i| la.axis(axis).angle(i).millidegrees() - lb.axis(axis).angle(i).millidegrees())
            .collect();
        let far = diff.iter().map(|d| d.abs()).max().unwrap();
        // Unrelated loops: degrees apart somewhere on every axis.
        assert!(far > 2000, "{axis:?}: at most {far} m° apart");
    }
    // A board without an id plays the paper's seeds, as before.
    assert_eq!(settings.idle_seeds(BoardId::NONE), PAPER);
    assert_eq!(loops(PAPER).axis(Axis::Yaw).angle(0), Angle::ZERO);
}

#[test]
fn the_seeds_of_many_ids_all_generate() {
    let settings = Settings::DEFAULT;
    // A spread of ids: small, large, one bit apart, random-looking.
    let mut id: u64 = 0x0123_4567_89ab_cdef;
    for k in 0..300_u64 {
        id = id
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1 + k);
        let _ = loops(settings.idle_seeds(BoardId(id)));
    }
    for small in 1..=20 {
        let _ = loops(settings.idle_seeds(BoardId(small)));
    }
}
