//! QEMU smoke image: the core and the frame task of the Pico image on an
//! emulated Cortex-M0 (`qemu-system-arm -machine lm3s6965evb -cpu cortex-m0`),
//! with three virtual PWM outputs, logging through defmt over semihosting.
//!
//! ```text
//! cargo xtask qemu        # from the repository root: build, run, decode,
//!                         # check the summary line and the log on file
//! cargo run --release     # in boards/qemu/: build, run, decode (see run.sh)
//! ```
//!
//! The run generates the three loops (and measures the cost), plays the
//! never-repeating idle with a fade-in (soft start) past its first join (the
//! next loop set, generated meanwhile by a low-priority task, blended in),
//! plays a script over it (a nod, a shake interrupted by a tilt, a look and
//! its return, see script.rs), injects PWM faults on the yaw servo (a short burst it survives, then a
//! persistent one that gets it switched off), fades out and ends with one
//! line:
//!
//! ```text
//! summary frames=<n> missed=<n> pulse_violations=<n> precompute_insns=<n> checksum=<hex> faults=<n> disabled=<n>
//! ```
//!
//! then exits 0, or 1 if any invariant failed (each failure is logged as an
//! error first). The checksum is compared with the host's by `cargo xtask`.
//!
//! The frames come [`SPEEDUP`] = 20 times faster than on the board (idle
//! time is not free under `-icount`): one every 1 ms, with the Pico's
//! configuration as it is, so frame `k` writes the pulses frame `k` writes
//! on the board. As on the Pico, the frame task runs above the loop
//! generator and the console (`executor.rs`).
#![no_std]
#![no_main]

mod checks;
mod console;
mod executor;
mod exit;
mod interactive;
mod pwm;
mod script;
#[allow(dead_code)] // its stopwatch is the bench's
mod systick;
mod uart;

use defmt_semihosting as _;
use idle_head_core::behaviour::BehaviourParams;
use idle_head_core::driver::{DriverConfig, DriverParams, FrameDriver};
use idle_head_core::motion::DEFAULT_N;
use idle_head_core::{Microseconds, Millis};
use idle_head_firmware::boot::{Generator, LINKS};
use idle_head_firmware::config::{DEFAULT_PARAMS, LOOP_DURATION};
use idle_head_firmware::tasks;

use crate::checks::Checks;
use crate::pwm::VirtualPwm;

/// How much faster than the Pico the smoke run plays (see the crate docs).
const SPEEDUP: u32 = 20;

/// The Pico's configuration: every per-frame quantity as on the board.
const CONFIG: DriverConfig = DriverConfig::DEFAULT;
/// The time between frames here: the Pico's, [`SPEEDUP`] times shorter.
const FRAME_PERIOD: Microseconds = Microseconds(CONFIG.frame_period.0 / SPEEDUP);
/// 30 s / 20 = 1.5 s per loop: 1500 frames of 1 ms, as many as the Pico's
/// (the frames play the Pico's loops and timing, `DEFAULT_TIMING`).
const LOOP: Millis = Millis(LOOP_DURATION.0 / SPEEDUP);

// The compression is exact: whole µs and ms, as many frames a loop.
const _: () = {
    assert!(FRAME_PERIOD.0 * SPEEDUP == CONFIG.frame_period.0);
    assert!(LOOP.0 * SPEEDUP == LOOP_DURATION.0);
};

/// Duty counts per PWM period of the virtual servo outputs: the Pico's `TOP`
/// (63 999: 64 000 counts per 20 ms from its 125 MHz clock), so that the duties
/// written here are the board's.
const PICO_TOP: u16 = idle_head_core::pwm_clock::PICO_SERVO_CLOCK.top;

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        exit::exit(false)
    };
    defmt::info!(
        "idle-head QEMU smoke run: {=u32}x time compression, frame period {=u32} us, loop {=u32} ms = {=u64} frames, N = {=usize}, fade {=u32} frames, disable after {=u16} failed frames",
        SPEEDUP,
        FRAME_PERIOD.0,
        LOOP.0,
        checks::LOOP_FRAMES,
        DEFAULT_N,
        DEFAULT_PARAMS.fade_frames(),
        DEFAULT_PARAMS.disable_frames()
    );
    defmt::info!(
        "virtual PWM: {=u16} counts per {=u32} us (the Pico's TOP), pulse limits [{=u32}, {=u32}] us",
        PICO_TOP,
        CONFIG.pwm.period.0,
        CONFIG.servos[0].min_pulse.0,
        CONFIG.servos[0].max_pulse.0
    );

    let Ok(booted) = console::boot() else {
        exit::exit(false)
    };
    let mode = console::Mode::from_host();
    console::set_mode(mode);
    match mode {
        console::Mode::Smoke => {}
        console::Mode::Held => {
            defmt::info!("console: the run lasts until the host hangs up (UART1)");
        }
        console::Mode::Interactive => defmt::info!(
            "interactive: a clean head at real time (frames of {=u32} us), no script, no faults, until the host hangs up (UART1)",
            CONFIG.frame_period.0
        ),
    }

    let period = match mode {
        console::Mode::Interactive => systick::INTERACTIVE_PERIOD,
        console::Mode::Smoke | console::Mode::Held => systick::DRIVER_PERIOD,
    };
    systick::start_time_driver(&mut core.SYST, period);

    let Some((thread, frame_executor)) = executor::take() else {
        exit::exit(false)
    };
    match generator(booted.generator) {
        Ok(token) => thread.spawner().spawn(token),
        Err(_) => exit::exit(false),
    }
    // Settings in Pico units (the frame task's behaviour is built for
    // them too); status reports Pico time (frames of 20 ms).
    let service = booted.service;
    let frame = embassy_time::Duration::from_micros(frame_period(mode).0.into());
    match console::console(service, frame) {
        Ok(token) => thread.spawner().spawn(token),
        Err(_) => exit::exit(false),
    }
    match frame_task(booted.driver, booted.behaviour) {
        Ok(token) => frame_executor.spawner().spawn(token),
        Err(_) => exit::exit(false),
    }
    executor::run(&mut core.NVIC, thread, frame_executor)
}

/// Generates loop set 0 (its cost measured in instructions: SysTick counts
/// 12.5 MHz, 80 instructions per count under `-icount shift=0`, see
/// systick.rs), then each next loop set while the frames play (thread mode).
#[embassy_executor::task]
async fn generator(generator: Generator) {
    tasks::generate(generator, systick::Instructions).await;
}

// The behaviour's parameters go to the task once, at boot.
#[allow(clippy::large_types_passed_by_value)]
#[embassy_executor::task]
async fn frame_task(params: DriverParams, behaviour: BehaviourParams) {
    let channels = CONFIG
        .servos
        .map(|servo| VirtualPwm::new(PICO_TOP, CONFIG.pwm.period, &servo));
    let mut driver = FrameDriver::new(channels, params);
    let mode = console::mode();
    let (first, run) = LINKS.exchange.first().await;
    if mode == console::Mode::Interactive {
        let mut hooks = interactive::Interactive::new(CONFIG.servos);
        let period = frame_period(mode);
        let (stats, _) =
            tasks::play(&mut driver, first, &behaviour, &mut hooks, period, &LINKS).await;
        let violations = channel_violations(&mut driver);
        summary(&stats, violations, &run, &driver);
        exit::exit(violations == 0 && stats.missed == 0);
    }
    // The script's commands share the console's queue, as a board's would.
    let mut checks = Checks::new(CONFIG, &LINKS.commands, mode.held());
    let (stats, idle) = tasks::play(
        &mut driver,
        first,
        &behaviour,
        &mut checks,
        FRAME_PERIOD,
        &LINKS,
    )
    .await;
    defmt::info!(
        "frame timing: {=u64} frames, {=u64} missed, wake-up at most {=u64} us after the deadline",
        stats.frames,
        stats.missed,
        embassy_time::Duration::from_ticks(stats.max_lateness).as_micros()
    );
    defmt::info!(
        "idle: {=u32} join(s), {=u32} late, playing loop set {=u32}",
        idle.joins,
        idle.late,
        idle.set
    );
    let ok = checks.finish(&stats, &idle, &mut driver, run.generated);
    let violations = channel_violations(&mut driver);
    summary(&stats, violations, &run, &driver);
    exit::exit(ok && violations == 0 && stats.missed == 0);
}

/// The time between frames: the smoke run's compressed one, or the
/// board's in an interactive run.
const fn frame_period(mode: console::Mode) -> Microseconds {
    match mode {
        console::Mode::Interactive => CONFIG.frame_period,
        console::Mode::Smoke | console::Mode::Held => FRAME_PERIOD,
    }
}

/// The pulses the virtual outputs judged outside the hard bounds.
fn channel_violations(driver: &mut FrameDriver<VirtualPwm>) -> u32 {
    let logs = driver.channels_mut().each_ref().map(|c| *c.log());
    logs.iter().map(|l| l.violations).sum()
}

/// The peak stack and the run's summary line.
fn summary(
    stats: &idle_head_firmware::frame::RunStats,
    violations: u32,
    run: &idle_head_firmware::exchange::FirstSet,
    driver: &FrameDriver<VirtualPwm>,
) {
    // The stack was painted before `main` (cortex-m-rt's `paint-stack`): the
    // bytes that lost their paint are the deepest the stack has been.
    defmt::info!(
        "stack: peak stack {=u32} B of {=u32} B",
        cortex_m_stack::stack_size().saturating_sub(cortex_m_stack::stack_painted()),
        cortex_m_stack::stack_size()
    );
    let driver_stats = driver.stats();
    let faults: u32 = driver_stats.faults.iter().sum();
    let disabled = driver_stats.disabled.iter().filter(|&&d| d).count();
    defmt::info!(
        "summary frames={=u64} missed={=u64} pulse_violations={=u32} precompute_insns={=u64} checksum={=u32:#010x} faults={=u32} disabled={=usize}",
        stats.frames,
        stats.missed,
        violations,
        run.precompute,
        run.checksum,
        faults,
        disabled
    );
}
