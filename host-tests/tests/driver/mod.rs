//! The frame driver by subject: duties written, faults, the limiter, the
//! fade, configuration and its errors, the frame clock, run-time changes,
//! property tests, and the default limits against the real idle loops.

mod clock;
mod config;
mod fade;
mod faults;
mod idle_loop;
mod limiter;
mod output;
mod properties;
mod reference;
mod relax;
mod runtime;

use embedded_hal_mock::eh1::pwm::Mock;
use host_tests::{Recorder, mdeg};
use idle_head_core::driver::{FrameDriver, FrameReport};

/// Checks that every expected PWM transaction happened.
fn done(driver: FrameDriver<Mock>) {
    for mut ch in driver.release() {
        ch.done();
    }
}

/// The duties of a report, `[pitch, roll, yaw]`.
fn duties(r: &FrameReport) -> [u16; 3] {
    r.servos.map(|s| s.duty.0)
}

/// The angles of a report in m°, `[pitch, roll, yaw]`.
fn angles(r: &FrameReport) -> [i32; 3] {
    r.servos.map(|s| s.angle.millidegrees())
}

/// Runs `frames` frames of constant `offsets` and returns the pitch angles (m°).
fn pitch_angles(d: &mut FrameDriver<Recorder>, offsets: [i32; 3], frames: usize) -> Vec<i32> {
    (0..frames)
        .map(|_| d.write_frame(mdeg(offsets)).servos[0].angle.millidegrees())
        .collect()
}

/// Three recording channels of 20 000 counts per period (1 count per µs).
fn recorders() -> [Recorder; 3] {
    [
        Recorder::new(20_000),
        Recorder::new(20_000),
        Recorder::new(20_000),
    ]
}
