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
//! # Time compression
//!
//! Idle time is not free under `-icount shift=0`: QEMU either lets the
//! virtual clock follow the wall clock while the core sleeps (the default,
//! `sleep=on`) or jumps it (`sleep=off`). To keep the run short either way
//! the smoke build plays its frames [`SPEEDUP`] = 20 times faster: one every
//! 1 ms instead of 20 ms, a 1.5 s loop instead of 30 s. Everything else is
//! the Pico's configuration as it is, driver and behaviour alike, whose
//! per-frame quantities (loop position, fade gain, step and acceleration
//! limits of the idle and gesture modes, gesture and gaze timing, fault
//! counts) all derive from the Pico's 20 ms frame period: frame `k` here
//! writes the same pulses as frame `k` on the board, and only the wall clock
//! between frames is shorter. The virtual PWM keeps the 50 Hz servo period. The whole run is
//! about 1.9 s of virtual time.
//!
//! # Priorities
//!
//! As on the Pico, the frame task runs above the loop generator: in a raw
//! embassy executor polled from interrupt 0 (GPIO port A on the LM3S6965,
//! unused here; cortex-m-rt's default vector table sends it to
//! `DefaultHandler`), while the generator runs in the thread-mode executor
//! of `main`. The pender pends interrupt 0 for the one and wakes the other
//! from `WFI`.
#![no_std]
#![no_main]

mod checks;
mod console;
mod exit;
mod pwm;
mod script;
mod systick;
mod uart;

use core::ptr;
use core::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use cortex_m_rt::exception;
use defmt_semihosting as _;
use embassy_executor::raw;
use embassy_time::{Duration, Instant};
use idle_head_core::console::ConsoleService;
use idle_head_core::driver::{DriverConfig, DriverParams, FrameDriver};
use idle_head_core::idle::{IdleMode, IdlePlayer, IdleTiming, LoopStream};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N};
use idle_head_core::settings::{RamStorage, Settings, SettingsSource};
use idle_head_core::{Axis, Microseconds, Millis, Playback};
use idle_head_firmware::frame::{
    Exchange, ExchangeSupply, FrameLoop, IDLE_MODE, LOOP_DURATION, SetRef,
};
use static_cell::ConstStaticCell;

use crate::checks::Checks;
use crate::pwm::VirtualPwm;

/// How much faster than the Pico the smoke run plays (see the crate docs).
const SPEEDUP: u32 = 20;

/// The Pico's configuration: every per-frame quantity as on the board.
const CONFIG: DriverConfig = DriverConfig::DEFAULT;
/// The time between frames here: the Pico's, [`SPEEDUP`] times shorter.
const FRAME_PERIOD: Microseconds = Microseconds(CONFIG.frame_period.0 / SPEEDUP);
const PARAMS: DriverParams = match CONFIG.build() {
    Ok(p) => p,
    Err(e) => panic!("{}", e.message()),
};
/// 30 s / 20 = 1.5 s per loop: 1500 frames of 1 ms.
const LOOP: Millis = Millis(LOOP_DURATION.0 / SPEEDUP);
const PLAYBACK: Playback = match Playback::new(LOOP, FRAME_PERIOD, DEFAULT_N) {
    Ok(p) => p,
    Err(_) => panic!("invalid playback parameters"),
};

/// Loops of 1500 frames joined over 100, as on the Pico.
const TIMING: IdleTiming = match IdleTiming::new(PLAYBACK) {
    Ok(t) => t,
    Err(e) => panic!("{}", e.message()),
};

// The compression is exact: whole µs and ms, as many frames a loop.
const _: () = {
    assert!(FRAME_PERIOD.0 * SPEEDUP == CONFIG.frame_period.0);
    assert!(LOOP.0 * SPEEDUP == LOOP_DURATION.0);
};

/// Duty counts per PWM period of the virtual servo outputs: the Pico's `TOP`
/// (63 999: 64 000 counts per 20 ms from its 125 MHz clock), so that the duties
/// written here are the board's.
const PICO_TOP: u16 = idle_head_core::pwm_clock::PICO_SERVO_CLOCK.top;

use idle_head_firmware::frame::Set;

/// The two loop set buffers, 2 · 5.4 KB: one plays while the generator
/// fills the other.
static SETS: ConstStaticCell<[Set; 2]> = ConstStaticCell::new([Set::new(), Set::new()]);

/// The channels the buffers go round through.
static EXCHANGE: Exchange = Exchange::new();

/// Set by the pender when a thread-mode task was woken, cleared by the idle loop.
static PENDED: AtomicBool = AtomicBool::new(false);

/// The frame task's executor, polled from [`FrameIrq`] once `main` has set it.
static FRAME_EXECUTOR: AtomicPtr<raw::Executor> = AtomicPtr::new(ptr::null_mut());

/// The interrupt the frame executor runs in: IRQ 0 (GPIO port A).
#[derive(Clone, Copy)]
struct FrameIrq;

// Note(unsafe): 0 is a valid interrupt number of the LM3S6965's NVIC.
unsafe impl InterruptNumber for FrameIrq {
    fn number(self) -> u16 {
        0
    }
}

/// The frame executor's pender context (the thread executor's is `usize::MAX`).
const FRAME_CONTEXT: usize = 0;

/// Wake-up hook of the raw executors: pend the frame interrupt, or note
/// that thread mode has work.
#[unsafe(export_name = "__pender")]
fn pender(context: *mut ()) {
    if context as usize == FRAME_CONTEXT {
        NVIC::pend(FrameIrq);
    } else {
        PENDED.store(true, Ordering::Release);
    }
}

/// A UART's interrupt line, for the NVIC.
#[derive(Clone, Copy)]
struct UartIrq(u16);

// Note(unsafe): 5 and 6 are UART0's and UART1's interrupt numbers on the
// LM3S6965.
unsafe impl InterruptNumber for UartIrq {
    fn number(self) -> u16 {
        self.0
    }
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == uart::UART0_IRQ as i16 {
        uart::UART0.on_interrupt();
    } else if irqn == uart::UART1_IRQ as i16 {
        uart::UART1.on_interrupt();
    } else if irqn == FrameIrq.number() as i16 {
        let executor = FRAME_EXECUTOR.load(Ordering::Acquire);
        // Note(unsafe): the executor is a `'static` singleton set before the
        // interrupt is unmasked, and polled from this handler only, which
        // does not preempt itself.
        if let Some(executor) = unsafe { executor.as_ref() } {
            unsafe { executor.poll() };
        }
    } else {
        defmt::error!("unexpected interrupt {=i16}", irqn);
        exit::exit(false);
    }
}

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
        PARAMS.fade_frames(),
        CONFIG.faults.disable_after
    );
    defmt::info!(
        "virtual PWM: {=u16} counts per {=u32} us (the Pico's TOP), pulse limits [{=u32}, {=u32}] us",
        PICO_TOP,
        CONFIG.pwm.period.0,
        CONFIG.servos[0].min_pulse.0,
        CONFIG.servos[0].max_pulse.0
    );

    let [first, spare] = SETS.take();
    // Precompute cost: SysTick counts 12.5 MHz, i.e. 80 instructions per
    // count under `-icount shift=0` (see systick.rs).
    let (generated, counts) = systick::stopwatch(&mut core.SYST, || first.generate(&DEFAULT_HEAD));
    let precompute_insns = counts * systick::INSNS_PER_COUNT;
    let checksum = first.checksum();
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
            defmt::error!(
                "trajectory generation failed: {=str} {=str}",
                e.axis.name(),
                e.error.message()
            );
            false
        }
    };
    defmt::info!(
        "precompute: {=u64} SysTick counts = {=u64} instructions; checksum {=u32:#010x}",
        counts,
        precompute_insns,
        checksum
    );
    let hold = console::held_by_host();
    console::HOLD.store(hold, Ordering::Relaxed);
    if hold {
        defmt::info!("console: the run lasts until the host hangs up (UART1)");
    }

    systick::start_time_driver(&mut core.SYST);

    let (Some(thread), Some(frame_executor)) = (
        cortex_m::singleton!(: raw::Executor = raw::Executor::new(usize::MAX as *mut ())),
        cortex_m::singleton!(: raw::Executor = raw::Executor::new(FRAME_CONTEXT as *mut ())),
    ) else {
        exit::exit(false)
    };
    let frame_executor: &'static raw::Executor = frame_executor;
    match IDLE_MODE {
        IdleMode::NeverRepeating => {
            // The stream starts from the boot set, whose pace it measures
            // (a fixed loop has no stream and skips that).
            let mut stream = LoopStream::new(DEFAULT_HEAD, &TIMING);
            stream.adopt(first);
            defmt::info!(
                "idle: never repeating, a new loop set every {=u32} frames, joined over {=u32}",
                TIMING.period(),
                TIMING.join_frames
            );
            EXCHANGE.give(spare);
            match generator(stream) {
                Ok(token) => thread.spawner().spawn(token),
                Err(_) => exit::exit(false),
            }
        }
        IdleMode::FixedLoop => defmt::info!("idle: the fixed loop, replayed every loop"),
    }
    // Settings in Pico units (the frame task's behaviour is built for
    // them too); status reports Pico time (frames of 20 ms).
    match ConsoleService::new(
        &console::QUEUE,
        &console::LINK,
        RamStorage::new(),
        DriverConfig::DEFAULT,
        Settings::DEFAULT,
        SettingsSource::Defaults,
    ) {
        Ok(mut service) => {
            service.add_entropy(checksum);
            match console::console(service) {
                Ok(token) => thread.spawner().spawn(token),
                Err(_) => exit::exit(false),
            }
        }
        Err(_) => exit::exit(false),
    }
    match frame_task(first, precompute_insns, checksum, generated) {
        Ok(token) => frame_executor.spawner().spawn(token),
        Err(_) => exit::exit(false),
    }
    FRAME_EXECUTOR.store(ptr::from_ref(frame_executor).cast_mut(), Ordering::Release);
    // Note(unsafe): the frame executor is published above, before its
    // interrupt can run.
    unsafe { NVIC::unmask(FrameIrq) };
    // The UARTs below the frame interrupt (priority 0): a frame preempts
    // their (short) handler, never the other way round.
    for irq in [uart::UART0_IRQ, uart::UART1_IRQ] {
        // Note(unsafe): priorities are set before the interrupts are
        // unmasked; their handlers share no state with a priority-based
        // critical section.
        unsafe {
            core.NVIC.set_priority(UartIrq(irq), 0x80);
            NVIC::unmask(UartIrq(irq));
        }
    }
    loop {
        // Note(unsafe): `poll` is called from this loop only, never
        // re-entrantly (the pender only sets a flag).
        unsafe { thread.poll() };
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

/// Generates each next loop set while the frames play (thread mode).
#[embassy_executor::task]
async fn generator(mut stream: LoopStream<DEFAULT_N>) {
    EXCHANGE
        .generate_seeded(&mut stream, Some(&console::LINK), |result, ticks| match result {
            // Virtual time under `-icount shift=0`: 1000 instructions a µs,
            // the frames that preempt the generator included.
            Ok(info) => defmt::info!(
                "loop set {=u32} ready in {=u64} instructions: seeds {:#010x} ({} discarded), entered at {}, join mismatch {} mdeg rms",
                info.number,
                Duration::from_ticks(ticks).as_micros() * 1000,
                info.seeds,
                info.discarded,
                info.starts,
                info.mismatch
            ),
            Err(e) => defmt::error!(
                "loop set failed: {=str} {=str}; trying the next seeds",
                e.axis.name(),
                e.error.message()
            ),
        })
        .await
}

#[embassy_executor::task]
async fn frame_task(first: SetRef, precompute_insns: u64, checksum: u32, generated: bool) {
    let channels = CONFIG
        .servos
        .map(|servo| VirtualPwm::new(PICO_TOP, CONFIG.pwm.period, &servo));
    let mut driver = FrameDriver::new(channels, PARAMS);
    let idle: IdlePlayer<SetRef, ExchangeSupply> =
        IdlePlayer::new(first, EXCHANGE.supply(), TIMING, IDLE_MODE);
    let start = Instant::now().as_ticks();
    let Ok(mut frames) =
        FrameLoop::new(idle, FRAME_PERIOD, embassy_time::TICK_HZ, start).map(|frames| {
            frames
                .with_commands(&console::QUEUE)
                .with_link(&console::LINK)
        })
    else {
        defmt::error!("frame period below one timer tick");
        exit::exit(false)
    };
    // The script's commands share the console's queue, as a board's would.
    let mut checks = Checks::new(
        CONFIG,
        &console::QUEUE,
        console::HOLD.load(Ordering::Relaxed),
    );
    let stats = idle_head_firmware::frame::run(&mut driver, &mut frames, &mut checks).await;
    defmt::info!(
        "frame timing: {=u64} frames, {=u64} missed, wake-up at most {=u64} us after the deadline",
        stats.frames,
        stats.missed,
        embassy_time::Duration::from_ticks(stats.max_lateness).as_micros()
    );
    let idle = frames.idle_mut().stats();
    defmt::info!(
        "idle: {=u32} join(s), {=u32} late, playing loop set {=u32}",
        idle.joins,
        idle.late,
        idle.set
    );
    let ok = checks.finish(&stats, &idle, &mut driver, generated);
    let logs = driver.channels_mut().each_ref().map(|c| *c.log());
    let violations: u32 = logs.iter().map(|l| l.violations).sum();
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
        precompute_insns,
        checksum,
        faults,
        disabled
    );
    exit::exit(ok && violations == 0 && stats.missed == 0);
}
