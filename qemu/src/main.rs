//! QEMU smoke image: the core and the frame task of the Pico image on an
//! emulated Cortex-M0 (`qemu-system-arm -machine lm3s6965evb -cpu cortex-m0`),
//! with three virtual PWM outputs, logging through defmt over semihosting.
//!
//! ```text
//! cargo xtask qemu        # from the repository root: build, run, decode,
//!                         # check the summary line and the log on file
//! cargo run --release     # in qemu/: build, run, decode (see run.sh)
//! ```
//!
//! The run generates the three loops (and measures the cost), plays a
//! little more than one whole loop with a fade-in (soft start), injects PWM
//! faults on the yaw servo (a short burst it survives, then a persistent
//! one that gets it switched off), fades out and ends with one line:
//!
//! ```text
//! summary frames=<n> missed=<n> pulse_violations=<n> precompute_insns=<n> checksum=<hex> faults=<n> disabled=<n>
//! ```
//!
//! then exits 0, or 1 if any invariant failed (each failure is logged as an
//! error first). The checksum is compared with the host's by `cargo xtask`.
//!
//! # Time compression
//!
//! Idle time is not free under `-icount shift=0`: QEMU either lets the
//! virtual clock follow the wall clock while the core sleeps (the default,
//! `sleep=on`) or jumps it (`sleep=off`). To keep the run short either way
//! the smoke build plays the Pico's configuration [`SPEEDUP`] = 20 times
//! faster: 1 ms frames instead of 20 ms, a 1.5 s loop instead of 30 s, and
//! speed and acceleration limits 20 and 20² times higher. Every per-frame
//! quantity (loop position, fade gain, step and acceleration limits, fault
//! counts) is then exactly the Pico's, so frame `k` here writes the same
//! pulses as frame `k` on the board; only the wall clock between frames is
//! shorter. The virtual PWM keeps the 50 Hz servo period. The whole run is
//! about 1.9 s of virtual time.
#![no_std]
#![no_main]

mod checks;
mod exit;
mod pwm;
mod systick;

use core::sync::atomic::{AtomicBool, Ordering};

use defmt_semihosting as _;
use embassy_executor::raw;
use embassy_time::Instant;
use idle_head::driver::{DriverConfig, DriverParams, FrameDriver};
use idle_head::firmware::rp2040_pwm::PICO_SERVO_CLOCK;
use idle_head::firmware::{self, FrameLoop, LOOP_DURATION};
use idle_head::motion::{DEFAULT_HEAD, DEFAULT_N, HeadTrajectories, Q16};
use idle_head::{Axis, Microseconds, Millis, Playback};

use crate::checks::Checks;
use crate::pwm::VirtualPwm;

/// How much faster than the Pico the smoke run plays (see the crate docs).
const SPEEDUP: u32 = 20;

/// The Pico's configuration, time-compressed by [`SPEEDUP`].
const CONFIG: DriverConfig = compress(DriverConfig::DEFAULT, SPEEDUP);
const PARAMS: DriverParams = match CONFIG.build() {
    Ok(p) => p,
    Err(e) => panic!("{}", e.message()),
};
/// 30 s / 20 = 1.5 s per loop: 1500 frames of 1 ms.
const LOOP: Millis = Millis(LOOP_DURATION.0 / SPEEDUP);
const PLAYBACK: Playback = match Playback::new(LOOP, CONFIG.frame_period, DEFAULT_N) {
    Ok(p) => p,
    Err(_) => panic!("invalid playback parameters"),
};

/// `config` played `k` times faster: frame period and fade `/ k`, speed
/// limit `· k`, acceleration limit `· k²`, fault log interval `/ k`. The
/// driver's per-frame step (speed · frame period) and per-frame² change
/// (acceleration · frame period²) stay the same. The PWM period is kept.
const fn compress(mut config: DriverConfig, k: u32) -> DriverConfig {
    config.frame_period = Microseconds(config.frame_period.0 / k);
    config.fade = Millis(config.fade.0 / k);
    config.faults.log_interval = Millis(config.faults.log_interval.0 / k);
    let mut i = 0;
    while i < 3 {
        config.motion[i].max_speed.0 *= k;
        config.motion[i].max_accel.0 *= k * k;
        i += 1;
    }
    config
}

// The compression is exact: whole µs and ms.
const _: () = {
    let pico = DriverConfig::DEFAULT;
    assert!(CONFIG.frame_period.0 * SPEEDUP == pico.frame_period.0);
    assert!(CONFIG.fade.0 * SPEEDUP == pico.fade.0);
    assert!(LOOP.0 * SPEEDUP == LOOP_DURATION.0);
};

type Head = HeadTrajectories<Q16, DEFAULT_N>;

/// The three loops: 3 · 900 · 2 B = 5400 B, generated once at boot.
static mut HEAD: Head = Head::new();

/// Set by the executor's pender (a task was woken), cleared by the idle loop.
static PENDED: AtomicBool = AtomicBool::new(false);

/// Wake-up hook of the raw executor: just note that there is work to do.
#[unsafe(export_name = "__pender")]
fn pender(_context: *mut ()) {
    PENDED.store(true, Ordering::Release);
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        exit::exit(false)
    };
    defmt::info!(
        "idle-head QEMU smoke run: {=u32}x time compression, frame period {=u32} us, loop {=u32} ms = {=u64} frames, N = {=usize}, fade {=u32} frames, disable after {=u16} failed frames",
        SPEEDUP,
        CONFIG.frame_period.0,
        LOOP.0,
        checks::LOOP_FRAMES,
        DEFAULT_N,
        PARAMS.fade_frames(),
        CONFIG.faults.disable_after
    );
    defmt::info!(
        "virtual PWM: {=u16} counts per {=u32} us (the Pico's TOP), pulse limits [{=u32}, {=u32}] us",
        PICO_SERVO_CLOCK.top,
        CONFIG.pwm.period.0,
        CONFIG.servos[0].min_pulse.0,
        CONFIG.servos[0].max_pulse.0
    );

    // Note(unsafe): the only reference ever made to HEAD, here, once, before
    // any task runs; it is handed on as a shared reference below.
    let head: &'static mut Head = unsafe { &mut *core::ptr::addr_of_mut!(HEAD) };
    // Precompute cost: SysTick counts 12.5 MHz, i.e. 80 instructions per
    // count under `-icount shift=0` (see systick.rs).
    let (generated, counts) = systick::stopwatch(&mut core.SYST, || head.generate(&DEFAULT_HEAD));
    let precompute_insns = counts * systick::INSNS_PER_COUNT;
    let head: &'static Head = head;
    let checksum = head.checksum();
    let generated = match generated {
        Ok(info) => {
            for (axis, info) in Axis::ALL.iter().zip(info.iter()) {
                defmt::info!(
                    "{=str}: split at sample {=u16} of {=u16} zero crossings, {=u16} up-steps",
                    axis.name(),
                    info.split,
                    info.crossings,
                    info.up_steps
                );
            }
            true
        }
        Err(e) => {
            defmt::error!("trajectory generation failed: {=str}", e.error.message());
            false
        }
    };
    defmt::info!(
        "precompute: {=u64} SysTick counts = {=u64} instructions; checksum {=u32:#010x}",
        counts,
        precompute_insns,
        checksum
    );

    systick::start_time_driver(&mut core.SYST);

    let Some(executor) =
        cortex_m::singleton!(: raw::Executor = raw::Executor::new(usize::MAX as *mut ()))
    else {
        exit::exit(false)
    };
    let spawner = executor.spawner();
    match frame_task(head, precompute_insns, checksum, generated) {
        Ok(token) => spawner.spawn(token),
        Err(_) => exit::exit(false),
    }
    loop {
        // Note(unsafe): `poll` is called from this loop only, never
        // re-entrantly (the pender only sets a flag).
        unsafe { executor.poll() };
        // Sleep until an interrupt unless a task was woken meanwhile. With
        // interrupts masked, WFI still wakes on a pending interrupt, which
        // then runs right after `free` returns: no wake-up is lost. QEMU
        // halts the core on WFI (WFE would spin: it is a no-op there).
        cortex_m::interrupt::free(|_| {
            if PENDED.load(Ordering::Acquire) {
                PENDED.store(false, Ordering::Relaxed);
            } else {
                cortex_m::asm::wfi();
            }
        });
    }
}

#[embassy_executor::task]
async fn frame_task(head: &'static Head, precompute_insns: u64, checksum: u32, generated: bool) {
    let channels = CONFIG
        .servos
        .map(|servo| VirtualPwm::new(PICO_SERVO_CLOCK.top, CONFIG.pwm.period, &servo));
    let mut driver = FrameDriver::new(channels, PARAMS);
    let loops = Axis::ALL.map(|axis| head.axis(axis));
    let start = Instant::now().as_ticks();
    let Ok(mut frames) = FrameLoop::new(PLAYBACK, loops, embassy_time::TICK_HZ, start) else {
        defmt::error!("frame period below one timer tick");
        exit::exit(false)
    };
    let mut checks = Checks::new(CONFIG);
    let stats = firmware::run(&mut driver, &mut frames, &mut checks).await;
    defmt::info!(
        "frame timing: {=u64} frames, {=u64} missed, wake-up at most {=u64} us after the deadline",
        stats.frames,
        stats.missed,
        embassy_time::Duration::from_ticks(stats.max_lateness).as_micros()
    );
    let ok = checks.finish(&stats, &mut driver, generated);
    let logs = driver.channels_mut().each_ref().map(|c| *c.log());
    let violations: u32 = logs.iter().map(|l| l.violations).sum();
    let driver_stats = driver.stats();
    let faults: u32 = driver_stats.faults.iter().sum();
    let disabled = driver_stats.disabled.iter().filter(|&&d| d).count();
    defmt::info!(
        "summary frames={=u64} missed={=u64} pulse_violations={=u32} precompute_insns={=u64} checksum={=u32:#010x} faults={=u32} disabled={=usize}",
        stats.frames,
        stats.missed,
        violations,
        precompute_insns,
        checksum,
        faults,
        disabled
    );
    exit::exit(ok && violations == 0 && stats.missed == 0);
}
