//! Link-time proof that the frame path cannot panic.
//!
//! ```text
//! cargo build --release --manifest-path qemu/Cargo.toml --bin frame-path-proof
//! ```
//!
//! (from the repository root; in qemu/, `cargo build --release --bin frame-path-proof`).
//!
//! This image runs the per-frame work of the firmware — [`FrameLoop::next`]
//! (frame clock) and [`FrameLoop::write`] (playback interpolation, fade,
//! limits, pulse and duty conversion, PWM writes and fault handling in
//! `FrameDriver::write_frame`) — on inputs the optimiser cannot see
//! through (`core::hint::black_box`): any time, any loop contents, any PWM
//! maximum, PWM writes that fail or not, stop and resume requests at any
//! frame. Its panic handler calls `frame_path_has_a_panic_path`, a function
//! that exists nowhere. If any panic (index, division, overflow check,
//! `unwrap`, ...) remains reachable after optimisation, the call survives
//! and the link fails:
//!
//! ```text
//! rust-lld: error: undefined symbol: frame_path_has_a_panic_path
//! ```
//!
//! A successful build is the proof, for the release profile the firmware is
//! built with. The image is never run. The driver parameters and the
//! playback are built outside the proof (at compile time, as in the board
//! images); only the frame work is covered.
#![no_std]
#![no_main]

use core::hint::black_box;

use embedded_hal::pwm::{ErrorKind, ErrorType, SetDutyCycle};
use idle_head::driver::{DriverConfig, DriverParams, FrameDriver};
use idle_head::firmware::{FrameLoop, LOOP_DURATION};
use idle_head::motion::{DEFAULT_N, HeadTrajectories, Q16};
use idle_head::{Axis, Playback};

const PARAMS: DriverParams = match DriverConfig::DEFAULT.build() {
    Ok(p) => p,
    Err(e) => panic!("{}", e.message()),
};
const PLAYBACK: Playback =
    match Playback::new(LOOP_DURATION, DriverConfig::DEFAULT.frame_period, DEFAULT_N) {
        Ok(p) => p,
        Err(_) => panic!("invalid playback parameters"),
    };

/// Loops with unknown contents (the optimiser sees them through `black_box`).
static HEAD: HeadTrajectories<Q16, DEFAULT_N> = HeadTrajectories::new();

/// A PWM channel whose maximum duty and write results are unknown.
struct OpaquePwm;

impl ErrorType for OpaquePwm {
    type Error = ErrorKind;
}

impl SetDutyCycle for OpaquePwm {
    fn max_duty_cycle(&self) -> u16 {
        black_box(u16::MAX)
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        if black_box(duty) == black_box(0) {
            Err(ErrorKind::Other)
        } else {
            Ok(())
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    unsafe extern "C" {
        /// Defined nowhere: the proof.
        fn frame_path_has_a_panic_path() -> !;
    }
    // Note(unsafe): never executed; the image only links if no call to this
    // handler is left.
    unsafe { frame_path_has_a_panic_path() }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let head = black_box(&HEAD);
    let loops = Axis::ALL.map(|axis| head.axis(axis));
    let mut driver = FrameDriver::new([OpaquePwm, OpaquePwm, OpaquePwm], black_box(PARAMS));
    let Ok(mut frames) = FrameLoop::new(
        black_box(PLAYBACK),
        loops,
        black_box(1_000_000),
        black_box(0),
    ) else {
        // Not reached with the built-in playback; no panic either way.
        loop {
            cortex_m::asm::wfi();
        }
    };
    loop {
        match black_box(0_u8) {
            1 => driver.request_stop(),
            2 => driver.resume(),
            _ => {}
        }
        let tick = frames.next(black_box(0));
        let written = frames.write(&mut driver, tick);
        black_box((written, driver.is_stopped(), driver.stats()));
    }
}
