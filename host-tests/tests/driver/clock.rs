//! The frame clock: deadlines without drift, late frames skipped without a
//! burst, saturation.

use idle_head_core::driver::{FrameClock, FrameTick, ZeroPeriod};

#[test]
fn frame_clock_runs_on_time_without_drift() {
    let mut c = FrameClock::new(20_000, 5).unwrap();
    for k in 0..1000u64 {
        assert_eq!(c.deadline(), 5 + 20_000 * k);
        // Woken a little late every time: no skipping, no drift.
        assert_eq!(
            c.tick(c.deadline() + 19_999),
            FrameTick {
                frame: k,
                skipped: 0
            }
        );
    }
    assert_eq!(c.skipped_total(), 0);
    assert_eq!(c.period(), 20_000);
}

#[test]
fn frame_clock_skips_late_frames_without_a_burst() {
    let mut c = FrameClock::new(100, 0).unwrap();
    assert_eq!(
        c.tick(0),
        FrameTick {
            frame: 0,
            skipped: 0
        }
    );
    // Frame 1 due at 100, served at 200: late by a whole period, frame 1 skipped.
    assert_eq!(
        c.tick(200),
        FrameTick {
            frame: 2,
            skipped: 1
        }
    );
    assert_eq!(c.deadline(), 300);
    // Served at 1350: frames 3..=12 missed, frame 13 played now, next due at 1400.
    assert_eq!(
        c.tick(1350),
        FrameTick {
            frame: 13,
            skipped: 10
        }
    );
    assert_eq!(c.deadline(), 1400);
    assert!(
        c.deadline() > 1350,
        "next deadline lies in the future: no catch-up burst"
    );
    // Early call: plays the due frame.
    assert_eq!(
        c.tick(1390),
        FrameTick {
            frame: 14,
            skipped: 0
        }
    );
    assert_eq!(c.deadline(), 1500);
    assert_eq!(c.skipped_total(), 11);
    // Frame index and time stay in step: frame k is due at k · period.
    assert_eq!(c.deadline(), 15 * 100);
}

#[test]
fn frame_clock_saturates_instead_of_overflowing() {
    assert_eq!(FrameClock::new(0, 0), Err(ZeroPeriod));
    let mut c = FrameClock::new(u64::MAX / 2, u64::MAX - 10).unwrap();
    c.tick(u64::MAX);
    assert_eq!(c.deadline(), u64::MAX);
    let t = c.tick(u64::MAX);
    assert_eq!(t.skipped, 0);
}
