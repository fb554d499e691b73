//! The frame clock: deadlines without drift, late frames skipped without a
//! burst, the frames' time in step with them, a change of period between
//! two frames, saturation.

use idle_head_core::driver::{FrameClock, ZeroPeriod};
use idle_head_core::{Microseconds, Timestamp};

/// The frame index, frames skipped and time of a tick.
fn tick(c: &mut FrameClock, now: u64) -> (u64, u64, u64) {
    let t = c.tick(now);
    // The ms clock is the µs one in whole ms (wrapping).
    assert_eq!(u64::from(t.ms), t.at.0 / 1000 % (1 << 32));
    (t.frame, t.skipped, t.at.0)
}

#[test]
fn frame_clock_runs_on_time_without_drift() {
    let mut c = FrameClock::new(20_000, 5, Microseconds(20_000)).unwrap();
    for k in 0..1000u64 {
        assert_eq!(c.deadline(), 5 + 20_000 * k);
        // Woken a little late every time: no skipping, no drift.
        let now = c.deadline() + 19_999;
        assert_eq!(tick(&mut c, now), (k, 0, 20_000 * k));
    }
    assert_eq!(c.skipped_total(), 0);
    assert_eq!(c.period(), 20_000);
}

#[test]
fn frame_clock_skips_late_frames_without_a_burst() {
    let mut c = FrameClock::new(100, 0, Microseconds(3003)).unwrap();
    assert_eq!(tick(&mut c, 0), (0, 0, 0));
    // Frame 1 due at 100, served at 200: late by a whole period, frame 1 skipped.
    assert_eq!(tick(&mut c, 200), (2, 1, 6006));
    assert_eq!(c.deadline(), 300);
    // Served at 1350: frames 3..=12 missed, frame 13 played now, next due at 1400.
    assert_eq!(tick(&mut c, 1350), (13, 10, 13 * 3003));
    assert_eq!(c.deadline(), 1400);
    assert!(
        c.deadline() > 1350,
        "next deadline lies in the future: no catch-up burst"
    );
    // Early call: plays the due frame.
    assert_eq!(tick(&mut c, 1390), (14, 0, 14 * 3003));
    assert_eq!(c.deadline(), 1500);
    assert_eq!(c.skipped_total(), 11);
    // Frame index and time stay in step: frame k is due at k · period.
    assert_eq!(c.deadline(), 15 * 100);
}

#[test]
fn a_new_period_counts_from_the_last_frame() {
    let mut c = FrameClock::new(20_000, 0, Microseconds(20_000)).unwrap();
    // Before the first frame: frame 0 stays due at the start.
    c.set_period(5_000, Microseconds(5_000));
    assert_eq!(c.deadline(), 0);
    assert_eq!(tick(&mut c, 0), (0, 0, 0));
    assert_eq!(tick(&mut c, 5_000), (1, 0, 5_000));
    // After frame 1: frame 2 comes one new period after it, and so on.
    c.set_period(3_003, Microseconds(3_003));
    assert_eq!(c.deadline(), 8_003);
    assert_eq!(tick(&mut c, 8_003), (2, 0, 8_003));
    assert_eq!(tick(&mut c, 11_006), (3, 0, 11_006));
    // Late by two periods at the new rate: two skipped, the time on by three.
    assert_eq!(tick(&mut c, 14_009 + 6_006), (6, 2, 20_015));
    // Back to 20 ms: the ms clock keeps the µs beyond whole ms.
    c.set_period(20_000, Microseconds(20_000));
    assert_eq!(c.deadline(), 40_015);
    assert_eq!(tick(&mut c, 40_015), (7, 0, 40_015));
    assert_eq!(c.frame_period(), Microseconds(20_000));
    assert_eq!(c.tick(60_015).at, Timestamp(60_015));
}

#[test]
fn frame_clock_saturates_instead_of_overflowing() {
    assert_eq!(FrameClock::new(0, 0, Microseconds(20_000)), Err(ZeroPeriod));
    let mut c = FrameClock::new(u64::MAX / 2, u64::MAX - 10, Microseconds(20_000)).unwrap();
    c.tick(u64::MAX);
    assert_eq!(c.deadline(), u64::MAX);
    let t = c.tick(u64::MAX);
    assert_eq!(t.skipped, 0);
}
