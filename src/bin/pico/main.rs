//! Raspberry Pi Pico (RP2040) firmware: three servos play the idle loop.
//!
//! `cargo run --release` builds this image and flashes it through a debug
//! probe with probe-rs; the log arrives over RTT (defmt).
//!
//! # Wiring
//!
//! | axis  | GPIO | Pico pin | PWM slice, channel |
//! |-------|------|----------|--------------------|
//! | pitch | GP16 | 21       | PWM0 A             |
//! | roll  | GP18 | 24       | PWM1 A             |
//! | yaw   | GP20 | 26       | PWM2 A             |
//!
//! (GPIO n drives PWM slice ⌊n/2⌋ mod 8, channel A for even n.) One slice per
//! servo, so each output starts on its own first valid pulse (`servo_pwm.rs`).
//! Servo signal wires to these pins, servo ground to a Pico GND (e.g. pin 23)
//! and to the servo supply's ground; power the servos from their own 5 to 6 V
//! supply, not from the Pico.
//!
//! # PWM timing
//!
//! 125 MHz system clock, 50 Hz: divider 38 + 3/16 = 38.1875, `TOP` = 65 465,
//! one count = 305.5 ns, period 19 999.86 µs (worked out in
//! `idle_head::firmware::rp2040_pwm`). A 1000..2000 µs servo range spans
//! 3273 counts.
//!
//! # Watchdog
//!
//! The hardware watchdog is started just before the first frame and fed by
//! the frame task after every frame, with [`WATCHDOG_TIMEOUT`] = 100 ms
//! (5 frames). If frames stop, the board resets; the next boot logs that the
//! last reset came from the watchdog and starts softly again: outputs low,
//! neutral pulses first, motion faded in.
//!
//! # Calibration
//!
//! `cargo run --release --features calibrate` plays a slow sweep of each
//! axis to its limits instead of the idle loop and logs the pulses there
//! (`calibrate.rs`).
#![no_std]
#![no_main]

#[cfg(feature = "calibrate")]
mod calibrate;
mod servo_pwm;

use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_rp::watchdog::{ResetReason, Watchdog};
use embassy_time::{Duration, Instant};
use idle_head::driver::{DriverConfig, DriverParams, FrameDriver};
use idle_head::firmware::rp2040_pwm::{PICO_SERVO_CLOCK, PICO_SYS_HZ};
use idle_head::firmware::{self, Flow, Frame, FrameHooks, FrameLoop, LOOP_DURATION};
use idle_head::motion::{DEFAULT_HEAD, DEFAULT_N, HeadTrajectories, Q16};
use idle_head::{Axis, Playback};
use panic_probe as _;

use crate::servo_pwm::ServoPwm;

/// The frame driver's configuration: 50 Hz frames and PWM, hobby servos on
/// the anatomical limits, a 2 s fade (see `DriverConfig::DEFAULT`).
const CONFIG: DriverConfig = DriverConfig::DEFAULT;
const PARAMS: DriverParams = match CONFIG.build() {
    Ok(p) => p,
    Err(e) => panic!("{}", e.message()),
};
/// A 30 s loop at 20 ms frames: 1500 frames per loop.
#[cfg(not(feature = "calibrate"))]
const PLAYBACK: Playback = match Playback::new(LOOP_DURATION, CONFIG.frame_period, DEFAULT_N) {
    Ok(p) => p,
    Err(_) => panic!("invalid playback parameters"),
};
const LOOP_FRAMES: u64 = LOOP_DURATION.0 as u64 * 1000 / CONFIG.frame_period.0 as u64;

/// Watchdog timeout: 100 ms = 5 frames of 20 ms. Long enough for a frame
/// that runs late, short enough that a stuck board stops driving its servos
/// quickly (a reset releases the pins: no pulses until the next soft start).
const WATCHDOG_TIMEOUT: Duration = Duration::from_millis(100);

type Head = HeadTrajectories<Q16, DEFAULT_N>;

/// The three loops: 3 · 900 · 2 B = 5400 B, generated once at boot.
static mut HEAD: Head = Head::new();

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_rp::init(embassy_rp::config::Config::default());
    let watchdog = Watchdog::new(p.WATCHDOG);
    match watchdog.reset_reason() {
        Some(ResetReason::TimedOut) => {
            defmt::warn!("boot: last reset by the WATCHDOG (frames had stopped); soft start again");
        }
        Some(ResetReason::Forced) => defmt::info!("boot: last reset forced (debugger or software)"),
        None => defmt::info!("boot: power-on or reset pin"),
    }

    // Outputs low from here until the first frame (see servo_pwm.rs).
    let clock = PICO_SERVO_CLOCK;
    let channels = [
        ServoPwm::new(p.PWM_SLICE0, p.PIN_16, &clock),
        ServoPwm::new(p.PWM_SLICE1, p.PIN_18, &clock),
        ServoPwm::new(p.PWM_SLICE2, p.PIN_20, &clock),
    ];
    defmt::info!(
        "servos: pitch GP16 (PWM0 A), roll GP18 (PWM1 A), yaw GP20 (PWM2 A); {=u32} Hz system clock, divider {=u8}+{=u8}/16, TOP {=u16}, {=u64} ps per count, period {=u64} ns",
        PICO_SYS_HZ,
        clock.divider_int(),
        clock.divider_frac(),
        clock.top,
        clock.count_ps(PICO_SYS_HZ),
        clock.period_ns(PICO_SYS_HZ)
    );
    defmt::info!(
        "motion: frame period {=u32} us, loop {=u32} ms = {=u64} frames of N = {=usize} samples, fade {=u32} frames",
        CONFIG.frame_period.0,
        LOOP_DURATION.0,
        LOOP_FRAMES,
        DEFAULT_N,
        PARAMS.fade_frames()
    );
    for (axis, servo) in Axis::ALL.iter().zip(CONFIG.servos.iter()) {
        defmt::info!(
            "{=str}: neutral {=u32} us, {=u32} ns/deg, pulses [{=u32}, {=u32}] us, limits [{=i32}, {=i32}] mdeg",
            axis.name(),
            servo.neutral.0,
            servo.per_degree.0,
            servo.min_pulse.0,
            servo.max_pulse.0,
            servo.limits.min.millidegrees(),
            servo.limits.max.millidegrees()
        );
    }

    // Note(unsafe): the only reference ever made to HEAD, here, once, before
    // the frame task exists; it is handed on as a shared reference below.
    let head: &'static mut Head = unsafe { &mut *core::ptr::addr_of_mut!(HEAD) };
    let start = Instant::now();
    let generated = head.generate(&DEFAULT_HEAD);
    let precompute_us = start.elapsed().as_micros();
    let head: &'static Head = head;
    match generated {
        Ok(info) => {
            for (axis, info) in Axis::ALL.iter().zip(info.iter()) {
                defmt::info!(
                    "{=str}: split at sample {=u16} of {=u16} zero crossings",
                    axis.name(),
                    info.split,
                    info.crossings
                );
            }
        }
        // The loop is left at the neutral pose: the servos hold still.
        Err(e) => defmt::error!("trajectory generation failed: {=str}", e.error.message()),
    }
    defmt::info!(
        "precompute: {=u64} us; checksum {=u32:#010x}",
        precompute_us,
        head.checksum()
    );

    let driver = FrameDriver::new(channels, PARAMS);
    match frame_task(driver, head, watchdog) {
        Ok(token) => spawner.spawn(token),
        Err(_) => defmt::error!("frame task already running"),
    }
}

#[embassy_executor::task]
async fn frame_task(mut driver: FrameDriver<ServoPwm>, head: &'static Head, watchdog: Watchdog) {
    #[cfg(not(feature = "calibrate"))]
    let (loops, playback) = (Axis::ALL.map(|axis| head.axis(axis)), PLAYBACK);
    #[cfg(feature = "calibrate")]
    let (sources, playback) = {
        let _ = head;
        let sweep = |axis: Axis| calibrate::Sweep::new(axis, CONFIG.servos[axis.index()].limits);
        (
            Axis::ALL.map(sweep),
            calibrate::playback(CONFIG.frame_period),
        )
    };
    #[cfg(feature = "calibrate")]
    let loops = [&sources[0], &sources[1], &sources[2]];
    let start = Instant::now().as_ticks();
    let Ok(mut frames) = FrameLoop::new(playback, loops, embassy_time::TICK_HZ, start) else {
        defmt::error!("frame period below one timer tick");
        return;
    };
    let mut hooks = PicoHooks::new(watchdog, playback);
    let stats = firmware::run(&mut driver, &mut frames, &mut hooks).await;
    // `PicoHooks` never stops; if it did, the watchdog would reset the board.
    defmt::error!("frame task ended: {}", stats);
}

/// Feeds the watchdog after every frame and logs a status line per loop.
struct PicoHooks {
    watchdog: Watchdog,
    #[cfg(feature = "calibrate")]
    playback: Playback,
    /// Frames per loop of the playback.
    loop_frames: u64,
    started: bool,
    max_lateness: u64,
}

impl PicoHooks {
    fn new(watchdog: Watchdog, playback: Playback) -> Self {
        let loop_ms = u64::from(playback.loop_duration().0);
        let frame_us = u64::from(playback.frame_period().0).max(1);
        Self {
            watchdog,
            #[cfg(feature = "calibrate")]
            playback,
            loop_frames: (loop_ms * 1000 / frame_us).max(1),
            started: false,
            max_lateness: 0,
        }
    }
}

impl FrameHooks<ServoPwm> for PicoHooks {
    fn after_frame(&mut self, frame: &Frame, driver: &mut FrameDriver<ServoPwm>) -> Flow {
        if self.started {
            self.watchdog.feed(WATCHDOG_TIMEOUT);
        } else {
            // The first frame (neutral pulses) is out: from now on frames
            // must keep coming.
            self.watchdog.start(WATCHDOG_TIMEOUT);
            self.started = true;
            let [p, r, y] = frame.report.servos;
            defmt::info!(
                "first frame: neutral pulses {=u32} {=u32} {=u32} us; watchdog armed ({=u64} ms)",
                p.pulse.0,
                r.pulse.0,
                y.pulse.0,
                WATCHDOG_TIMEOUT.as_millis()
            );
        }
        self.max_lateness = self
            .max_lateness
            .max(frame.woke.saturating_sub(frame.deadline));
        #[cfg(feature = "calibrate")]
        calibrate::log_frame(frame, &self.playback);
        let index = frame.tick.frame;
        if index > 0 && index.is_multiple_of(self.loop_frames) {
            let stats = driver.stats();
            defmt::info!(
                "loop {=u64} done: {=u64} frames written, wake-up at most {=u64} us late, faults {}, disabled {}",
                index / self.loop_frames,
                stats.frames,
                Duration::from_ticks(self.max_lateness).as_micros(),
                stats.faults,
                stats.disabled
            );
        }
        Flow::Continue
    }
}
