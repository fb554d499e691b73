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
//! 125 MHz system clock, exactly 50 Hz: divider 39 + 1/16 = 39.0625, `TOP` =
//! 63 999, one count = 312.5 ns, period 20 000 µs (worked out in
//! `idle_head_core::pwm_clock`). A 1000..2000 µs servo range spans 3200 counts.
//!
//! # Idle motion and priorities
//!
//! The head plays the never-repeating idle (`idle_head_core::idle`; the paper's
//! fixed loop with `--features fixed-loop`). The frame task runs in an
//! interrupt executor on `SWI_IRQ_1`, above the thread-mode executor where
//! the loop generator runs: generating a set takes about 2 ms of CPU, which
//! frames preempt, so a frame is never delayed by it. Two loop set buffers
//! change hands through the one-slot channels of [`Exchange`].
//!
//! # Watchdog
//!
//! The hardware watchdog is started just before the first frame and fed by
//! the frame task after every frame, with [`WATCHDOG_TIMEOUT`] = 100 ms
//! (5 frames). If frames stop, the board resets; the next boot logs that the
//! last reset came from the watchdog and starts softly again: outputs low,
//! neutral pulses first, motion faded in.
//!
//! # Stack
//!
//! cortex-m-rt paints the whole stack region before `main` (feature
//! `paint-stack`); the first frame's log line and each loop's status line
//! report the peak stack use since reset, the bytes that lost their paint
//! (`cortex-m-stack`). The loop generator (at boot and in its task) is the
//! deepest point, with a frame preempting it on top.
//!
//! # Watchdog drill
//!
//! `--features watchdog-drill` builds a test image, never shipped: frames
//! stop after [`DRILL_FRAMES`] frames of every boot, so that the watchdog
//! resets the board. `cargo xtask test` runs it in the RP2040 emulator and
//! checks the next boot: the watchdog reset logged, neutral pulses first, the
//! motion faded in.
//!
//! # Console (feature `console`)
//!
//! `--features console` adds the command protocol of `docs/protocol.md` on
//! two ports at once, each
//! with its own session (`console.rs`): UART0 on GP0 (TX, pin 1) and GP1
//! (RX, pin 2) at 115200 8N1, 3.3 V levels; and the board's USB port as a
//! CDC-ACM serial port, `16c0:27dd` (`usb.rs`). Both tasks run in thread
//! mode and share one `ConsoleService` (`handler.rs`), which hands actions to
//! the frame task through the command queue, which it drains between frames,
//! and servo calibrations, seeds and the head's status through the
//! `ConsoleLink`; the ports' interrupts sit below the frame task's.
//!
//! # Settings
//!
//! The last four 4 KiB flash sectors, `0x101f_c000..0x1020_0000`, hold the
//! settings store; memory.x reserves them in every image. With the
//! `console` feature the store is read at boot, before the first frame:
//! stored settings are put in effect (servo calibrations, behaviour, idle
//! seeds), else the built-in ones, and the log says which (`settings.rs`).
//! While `save` or `load` uses the flash, the frames feed the watchdog with
//! a longer timeout: a sector erase keeps interrupts off for up to 400 ms.
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
mod console;
mod panic;
mod servo_pwm;
mod settings;
mod usb;

use defmt_rtt as _;
use embassy_executor::{InterruptExecutor, Spawner};
use embassy_rp::interrupt::{self, InterruptExt, Priority};
use embassy_rp::watchdog::{ResetReason, Watchdog};
use embassy_time::{Duration, Instant};
use idle_head_core::behaviour::CommandQueue;
use idle_head_core::console::{ConsoleLink, ConsoleService};
use idle_head_core::driver::{DriverConfig, DriverParams, FrameDriver};
use idle_head_core::idle::{IdleMode, IdleTiming, LoopStream};
use idle_head_core::motion::DEFAULT_N;
use idle_head_core::{Axis, Playback};
use idle_head_firmware::frame::{
    DEFAULT_PARAMS, DEFAULT_TIMING, Exchange, Flow, Frame, FrameHooks, FrameLoop, IDLE_MODE,
    LOOP_DURATION, Set, SetRef,
};
use static_cell::ConstStaticCell;

use crate::servo_pwm::ServoPwm;
use idle_head_core::pwm_clock::{PICO_SERVO_CLOCK, PICO_SYS_HZ};

/// The frame driver's configuration: 50 Hz frames and PWM, hobby servos on
/// the anatomical limits, a 2 s fade (see `DriverConfig::DEFAULT`).
const CONFIG: DriverConfig = DriverConfig::DEFAULT;
const PARAMS: DriverParams = DEFAULT_PARAMS;
/// Loops of 1500 frames joined over 100: a join every 1400 frames.
const TIMING: IdleTiming = DEFAULT_TIMING;
const LOOP_FRAMES: u64 = LOOP_DURATION.0 as u64 * 1000 / CONFIG.frame_period.0 as u64;

/// Watchdog timeout: 100 ms = 5 frames of 20 ms. Long enough for a frame
/// that runs late, short enough that a stuck board stops driving its servos
/// quickly (a reset releases the pins: no pulses until the next soft start).
const WATCHDOG_TIMEOUT: Duration = Duration::from_millis(100);

/// Frames of each boot after which the drill image stops its frames: 3 s,
/// the 2 s fade-in and a second of motion.
#[cfg(feature = "watchdog-drill")]
const DRILL_FRAMES: u64 = 150;

/// The two loop set buffers, 2 · 5.4 KB: one plays while the generator
/// fills the other. All zero (the neutral pose) until generated.
static SETS: ConstStaticCell<[Set; 2]> = ConstStaticCell::new([Set::new(), Set::new()]);

/// The channels the buffers go round through.
static EXCHANGE: Exchange = Exchange::new();

/// Actions from the console ports to the frame task, which it drains
/// between frames.
static COMMANDS: CommandQueue = CommandQueue::new();

/// Status, servo calibrations and seeds between the console and the frame
/// task (and the loop generator).
static LINK: ConsoleLink = ConsoleLink::new();

/// The built-in settings, checked with [`CONFIG`] at compile time.
const DEFAULT_SETTINGS: idle_head_core::settings::Validated =
    match idle_head_core::settings::Settings::DEFAULT.validate(&CONFIG) {
        Ok(v) => v,
        Err(_) => panic!("the built-in settings fail validation"),
    };

/// The console service, shared by the two ports (thread mode only).
static SERVICE: static_cell::StaticCell<console::Service> = static_cell::StaticCell::new();

/// The frame task's executor, above thread mode.
static FRAME_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

#[embassy_rp::interrupt]
unsafe fn SWI_IRQ_1() {
    // Note(unsafe): called from this interrupt only, which `start` below
    // enables after the executor is set up.
    unsafe { FRAME_EXECUTOR.on_interrupt() }
}

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

    // Before the first frame: nothing else runs yet while the store is read.
    let boot = settings::boot(p.FLASH, &CONFIG, DEFAULT_SETTINGS, &LINK);
    let (boot_head, params, behaviour) = (boot.head(), boot.valid.driver, boot.valid.behaviour);
    let head = &boot_head;

    let [first, spare] = SETS.take();
    let start = Instant::now();
    let generated = first.generate(head);
    let precompute_us = start.elapsed().as_micros();
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
        Err(e) => defmt::error!(
            "trajectory generation failed: {=str} {=str}",
            e.axis.name(),
            e.error.message()
        ),
    }
    defmt::info!(
        "precompute: {=u64} us; checksum {=u32:#010x}",
        precompute_us,
        first.checksum()
    );
    match IDLE_MODE {
        IdleMode::NeverRepeating => {
            // The stream starts from the boot set, whose pace it measures
            // (a fixed loop has no stream and skips that).
            let mut stream = LoopStream::new(*head, &TIMING);
            stream.adopt(first);
            defmt::info!(
                "idle: never repeating, a new loop set every {=u32} frames, joined over {=u32}",
                TIMING.period(),
                TIMING.join_frames
            );
            EXCHANGE.give(spare);
            match generator(stream) {
                Ok(token) => spawner.spawn(token),
                Err(_) => defmt::error!("generator task already running"),
            }
        }
        IdleMode::FixedLoop => defmt::info!("idle: the fixed loop, replayed every loop"),
    }

    let driver = FrameDriver::new(channels, params);
    // The frame task's interrupt: above thread mode, below the time
    // driver's alarm (priority 0), which wakes it.
    interrupt::SWI_IRQ_1.set_priority(Priority::P1);
    let frames = FRAME_EXECUTOR.start(interrupt::SWI_IRQ_1);
    let checksum = first.checksum();
    let task = frame_task(driver, first, watchdog, behaviour);
    match task {
        Ok(token) => frames.spawn(token),
        Err(_) => defmt::error!("frame task already running"),
    }

    {
        let settings::Boot {
            storage,
            settings,
            source,
            ..
        } = boot;
        match ConsoleService::new(&COMMANDS, &LINK, storage, CONFIG, settings, source) {
            Ok(mut service) => {
                // `seed random` mixes in the ring oscillator's jitter (the
                // loop checksum and the boot time alone are the same on
                // every boot of the same settings), and the frame count when
                // it is asked.
                service
                    .add_entropy(checksum ^ Instant::now().as_ticks() as u32 ^ oscillator_jitter());
                let service = SERVICE.init(embassy_sync::blocking_mutex::Mutex::new(
                    core::cell::RefCell::new(service),
                ));
                console::start(
                    spawner,
                    console::Ports {
                        uart: p.UART0,
                        tx: p.PIN_0,
                        rx: p.PIN_1,
                        usb: p.USB,
                    },
                    service,
                );
            }
            Err(e) => defmt::error!("console: no service: {}", e),
        }
    }
}

/// 32 bits from the ring oscillator's RANDOMBIT: its jitter against the
/// system clock, different on every boot and board. The ROSC keeps
/// running beside the crystal in embassy-rp's default clock configuration.
/// Its bits are not uniform, so 64 are folded into 32; the console's
/// `seed random` stirs them further.
fn oscillator_jitter() -> u32 {
    let bits = embassy_rp::clocks::RoscRng.next_u64();
    bits as u32 ^ (bits >> 32) as u32
}

/// Generates each next loop set while the frames play (thread mode).
#[embassy_executor::task]
async fn generator(mut stream: LoopStream<DEFAULT_N>) {
    let generated = EXCHANGE.generate_seeded(&mut stream, Some(&LINK), log_set);
    generated.await
}

/// Logs a loop set the generator made.
fn log_set(
    result: &Result<idle_head_core::idle::SetInfo, idle_head_core::motion::AxisError>,
    ticks: u64,
) {
    match result {
        Ok(info) => defmt::info!(
            "loop set {=u32} ready in {=u64} us: seeds {:#010x} ({} discarded), entered at {}, join mismatch {} mdeg rms",
            info.number,
            Duration::from_ticks(ticks).as_micros(),
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
    }
}

/// The idle motion the frame task plays.
#[cfg(not(feature = "calibrate"))]
type Idle = idle_head_core::idle::IdlePlayer<SetRef, idle_head_firmware::frame::ExchangeSupply>;
#[cfg(feature = "calibrate")]
type Idle = idle_head_core::playback::Player<'static, calibrate::Sweep>;

#[embassy_executor::task]
async fn frame_task(
    mut driver: FrameDriver<ServoPwm>,
    first: SetRef,
    watchdog: Watchdog,
    behaviour: idle_head_core::behaviour::BehaviourParams,
) {
    #[cfg(not(feature = "calibrate"))]
    let (idle, playback): (Idle, _) = (
        idle_head_core::idle::IdlePlayer::new(first, EXCHANGE.supply(), TIMING, IDLE_MODE),
        // A 30 s loop at 20 ms frames: 1500 frames per loop.
        idle_head_firmware::frame::DEFAULT_PLAYBACK,
    );
    #[cfg(feature = "calibrate")]
    let (idle, playback): (Idle, _) = {
        use static_cell::StaticCell;
        static SWEEPS: StaticCell<[calibrate::Sweep; 3]> = StaticCell::new();
        let _ = first;
        let sweep = |axis: Axis| calibrate::Sweep::new(axis, CONFIG.servos[axis.index()].limits);
        let sweeps: &'static [calibrate::Sweep; 3] = SWEEPS.init(Axis::ALL.map(sweep));
        let playback = calibrate::playback(CONFIG.frame_period);
        (
            idle_head_core::playback::Player::new(playback, [&sweeps[0], &sweeps[1], &sweeps[2]]),
            playback,
        )
    };
    let start = Instant::now().as_ticks();
    // The console image: the behaviour of the settings the board booted with.
    let frames = FrameLoop::with_behaviour(
        idle,
        playback.frame_period(),
        behaviour,
        embassy_time::TICK_HZ,
        start,
    );
    let Ok(frames) = frames else {
        defmt::error!("frame period below one timer tick");
        return;
    };
    let frames = frames.with_commands(&COMMANDS).with_link(&LINK);
    let mut frames = frames;
    let mut hooks = PicoHooks::new(watchdog, playback);
    let stats = idle_head_firmware::frame::run(&mut driver, &mut frames, &mut hooks).await;
    // `PicoHooks` only stops in the watchdog drill; then the watchdog resets
    // the board.
    defmt::error!("frame task ended: {}", stats);
    // The drill stalls here, a hung frame task: the PWM keeps sending the
    // last pulse until the reset (returning would drop the driver, whose
    // slices switch off at once, mid-pulse).
    #[cfg(feature = "watchdog-drill")]
    core::future::pending::<()>().await;
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
            self.watchdog.feed(watchdog_timeout());
        } else {
            // The first frame (neutral pulses) is out: from now on frames
            // must keep coming.
            self.watchdog.start(WATCHDOG_TIMEOUT);
            self.started = true;
            let [p, r, y] = frame.report.servos;
            defmt::info!(
                "first frame: neutral pulses {=u32} {=u32} {=u32} us; watchdog armed ({=u64} ms); peak stack {=u32} B",
                p.pulse.0,
                r.pulse.0,
                y.pulse.0,
                WATCHDOG_TIMEOUT.as_millis(),
                peak_stack()
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
                "loop {=u64} done: {=u64} frames written, wake-up at most {=u64} us late, faults {}, disabled {}, peak stack {=u32} B",
                index / self.loop_frames,
                stats.frames,
                Duration::from_ticks(self.max_lateness).as_micros(),
                stats.faults,
                stats.disabled,
                peak_stack()
            );
        }
        #[cfg(feature = "watchdog-drill")]
        if index == DRILL_FRAMES {
            defmt::warn!(
                "watchdog drill: frames stop after frame {=u64}; the watchdog must reset the board",
                index
            );
            return Flow::Stop;
        }
        Flow::Continue
    }
}

/// The watchdog timeout the frame task feeds: [`WATCHDOG_TIMEOUT`], or
/// longer while the console's `save` or `load` uses the flash (see
/// `settings.rs`).
fn watchdog_timeout() -> Duration {
    if settings::FLASH_BUSY.load(core::sync::atomic::Ordering::Acquire) {
        Duration::from_millis(settings::FLASH_WATCHDOG_MS)
    } else {
        WATCHDOG_TIMEOUT
    }
}

/// Bytes of stack used since reset: the stack region was painted before
/// `main`, and the deepest write is the lowest word that lost its paint.
fn peak_stack() -> u32 {
    cortex_m_stack::stack_size().saturating_sub(cortex_m_stack::stack_painted())
}
