//! idle-head on the Raspberry Pi RP2040 and RP2350 (embassy-rp): what the
//! Pico and Pico 2 boards share, so that a board file only says which pins
//! and peripherals go where.
//!
//! A board makes the [`Board`] (the three servo outputs and the watchdog,
//! and whichever of the console's UART and USB port, the flash, the DMX
//! receiver, the trigger inputs and the radar it has: see [`Board`]) and calls
//! [`start`], which runs the firmware layer's boot sequence and spawns, by
//! priority, the tasks of the parts there are:
//!
//! | priority | what | runs |
//! |---|---|---|
//! | `P0` | the timer's alarm, the DMX512 receiver ([`dmx`]) | interrupts, microseconds each |
//! | `P1` | the frame task | an interrupt executor on `SWI_IRQ_1` |
//! | `P2` | the console on the UART and USB, the USB device, the trigger inputs ([`input`]), and their interrupts; the radar's receiver ([`radar`]) | an interrupt executor on `SWI_IRQ_0` ([`PORT_PRIORITY`]); the radar's timer alarm |
//! | thread mode | the loop generator, the status report ([`report`](idle_head_firmware::report)) | what is left |
//!
//! Nothing a person or a show waits for sits behind the loop generator
//! (tens of ms of work every loop) or the stack scan: they run in thread
//! mode, below everything else. [`waits`] measures how long the port tasks
//! wait for the CPU.
//!
//! Exactly one chip feature: `rp2040` or `rp235xa`.
#![no_std]

#[cfg(all(feature = "rp2040", feature = "rp235xa"))]
compile_error!("choose one chip: the `rp2040` or the `rp235xa` feature");
#[cfg(not(any(feature = "rp2040", feature = "rp235xa")))]
compile_error!("choose a chip: the `rp2040` or the `rp235xa` feature");

mod board;
pub mod dmx;
pub mod flash;
pub mod input;
mod panic;
pub mod pico;
pub mod pwm;
pub mod radar;
pub mod uart;
pub mod usb;
pub mod waits;

use core::cell::RefCell;

use embassy_executor::{InterruptExecutor, Spawner};
use embassy_rp::interrupt::{self, InterruptExt, Priority};
use embassy_rp::peripherals::USB;
use embassy_rp::watchdog::{ResetReason, Watchdog as RpWatchdog};
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_time::Duration;

use idle_head_core::behaviour::BehaviourParams;
use idle_head_core::console::{BoardParts, SharedService};
use idle_head_core::driver::{DriverConfig, DriverParams, FrameDriver};
use idle_head_core::seed::BoardId;
use idle_head_firmware::boot::{self, Clock, FLASH_BUSY, Generator, LINKS, Loaded};
use idle_head_firmware::hooks::{BoardHooks, Watchdog};
use static_cell::StaticCell;

pub use crate::board::Board;
use crate::board::Wired;
use crate::dmx::DmxUart;
use crate::input::GpioInputs;
use crate::pwm::ServoPwm;
use crate::radar::RadarRx;
use crate::uart::UartPort;
use crate::usb::UsbPort;
use idle_head_firmware::console::{Gone, Port, Received};

/// The servo outputs' slice clock at boot: exactly 50 Hz from [`SYS_HZ`]
/// (see `idle_head_core::pwm_clock`; the frame task sets the settings'
/// rate before the first pulse).
#[cfg(feature = "rp2040")]
pub use idle_head_core::pwm_clock::PICO_SERVO_CLOCK as SERVO_CLOCK;
/// The system clock embassy-rp's default configuration runs the chip at.
#[cfg(feature = "rp2040")]
pub use idle_head_core::pwm_clock::PICO_SYS_HZ as SYS_HZ;
/// The servo outputs' slice clock at boot: exactly 50 Hz from [`SYS_HZ`]
/// (see `idle_head_core::pwm_clock`; the frame task sets the settings'
/// rate before the first pulse).
#[cfg(feature = "rp235xa")]
pub use idle_head_core::pwm_clock::PICO2_SERVO_CLOCK as SERVO_CLOCK;
/// The system clock embassy-rp's default configuration runs the chip at.
#[cfg(feature = "rp235xa")]
pub use idle_head_core::pwm_clock::PICO2_SYS_HZ as SYS_HZ;

embassy_rp::bind_interrupts!(
    /// The interrupts of the drivers a board makes for its parts, bound
    /// once here for every board: the USB driver
    /// (`embassy_rp::usb::Driver::new(p.USB, Irqs)`) and PIO0, which the
    /// radar's receiver runs on (`Pio::new(p.PIO0, Irqs)`).
    pub struct Irqs {
        USBCTRL_IRQ => embassy_rp::usb::InterruptHandler<USB>;
        PIO0_IRQ_0 => embassy_rp::pio::InterruptHandler<embassy_rp::peripherals::PIO0>;
    }
);

/// The port tasks' executor and their interrupts: below the frame task's
/// (`P1`), above thread mode.
pub const PORT_PRIORITY: Priority = Priority::P2;

/// The frame driver's configuration: 50 Hz frames and PWM, hobby servos on
/// the anatomical limits, a 2 s fade (see `DriverConfig::DEFAULT`).
const CONFIG: DriverConfig = DriverConfig::DEFAULT;

/// The console service, shared by the ports (the port executor only).
/// (`None`: a board without a settings store.)
type Service = SharedService<flash::Storage>;
static SERVICE: StaticCell<Service> = StaticCell::new();

/// The frame task's executor, above thread mode.
static FRAME_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

/// The port tasks' executor, below the frame task's.
static PORT_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

#[embassy_rp::interrupt]
unsafe fn SWI_IRQ_1() {
    // Note(unsafe): called from this interrupt only, which `start` enables
    // after the executor is set up.
    unsafe { FRAME_EXECUTOR.on_interrupt() }
}

#[embassy_rp::interrupt]
unsafe fn SWI_IRQ_0() {
    // Note(unsafe): as for `SWI_IRQ_1`.
    unsafe { PORT_EXECUTOR.on_interrupt() }
}

/// Boots the head on `board` and spawns its tasks (see the crate docs);
/// `spawner` is the thread-mode executor's. Call once, from `main`.
///
/// Each step is a function of its own, out of line, so that what one step
/// holds on the stack (the settings store and the record it reads, the
/// console service on its way to its static, the USB builder) is gone
/// before the next: the boot's stack is the deepest step's, not their sum.
pub fn start(spawner: Spawner, board: Board) {
    let parts = board.parts();
    let Board {
        name,
        servos,
        servo_pins,
        watchdog,
        uart,
        usb,
        flash,
        dmx,
        inputs,
        radar,
    } = board;
    let watchdog = RpWatchdog::new(watchdog);
    let reason = watchdog.reset_reason();
    WATCHDOG.lock(|cell| cell.replace(Some(watchdog)));
    match reason {
        Some(ResetReason::TimedOut) => {
            defmt::warn!("boot: last reset by the WATCHDOG (frames had stopped); soft start again");
        }
        Some(ResetReason::Forced) => defmt::info!("boot: last reset forced (debugger or software)"),
        None => defmt::info!("boot: power-on or reset pin"),
    }
    log_clocks(name, servo_pins);
    // Before the first frame: nothing else runs yet while the unique id and
    // the store are read.
    let Some((loaded, id)) = open_store(flash) else {
        defmt::error!("boot: called twice");
        return;
    };
    log_id(id);
    let Some(head) = boot_head(spawner, loaded, id, parts) else {
        return;
    };
    spawn_frames(servos, &head, BoardWatchdog);
    if let Some(dmx) = dmx {
        spawn_dmx(dmx);
    }
    if let Some(radar) = radar {
        spawn_radar(radar);
    }
    interrupt::SWI_IRQ_0.set_priority(PORT_PRIORITY);
    interrupt::IO_IRQ_BANK0.set_priority(PORT_PRIORITY);
    interrupt::USBCTRL_IRQ.set_priority(PORT_PRIORITY);
    let executor = PORT_EXECUTOR.start(interrupt::SWI_IRQ_0);
    let parts = Ports {
        inputs,
        uart,
        usb,
        service: head.service,
    };
    if let Ok(token) = ports_task(parts) {
        executor.spawn(token);
    } else {
        defmt::error!("port tasks already running");
    }
    spawn(spawner, report_task(), "report");
}

/// The settings store on `flash` and the board's id, or the built-in
/// settings and no id on a board without one. `None` if called twice.
#[inline(never)]
fn open_store(
    flash: Option<embassy_rp::Peri<'static, embassy_rp::peripherals::FLASH>>,
) -> Option<(Loaded<flash::Storage>, BoardId)> {
    match flash {
        Some(flash) => flash::open(flash, &CONFIG, feed_watchdog, &FLASH_BUSY),
        None => Some(no_store()),
    }
}

/// The built-in settings on a board without a settings store (out of
/// line: the settings it holds are not on the stack under the store's
/// reading).
#[inline(never)]
fn no_store() -> (Loaded<flash::Storage>, BoardId) {
    defmt::info!("settings: built-in (this board has no settings store)");
    (Loaded::defaults(None), BoardId::NONE)
}

/// What the port executor's tasks start from.
struct Ports {
    inputs: Option<Wired<GpioInputs>>,
    uart: Option<Wired<UartPort>>,
    usb: Option<embassy_rp::usb::Driver<'static, USB>>,
    service: &'static Service,
}

// Note(unsafe): the console service's mutex is a `NoopRawMutex`, for one
// executor. Its reference goes from the boot to the port executor once,
// before any task uses it, and every task that uses it runs there.
unsafe impl Send for Ports {}

/// Spawns the port tasks in the port executor, from within it: the USB
/// device and its serial port are made here, as tasks of this executor
/// only can hold them (they are not `Send`).
#[embassy_executor::task]
async fn ports_task(parts: Ports) {
    // Note(unsafe): polled by the port executor, as the one way to spawn
    // tasks that are not `Send` in an interrupt executor.
    let spawner = unsafe { Spawner::for_current_executor() }.await;
    if let Some(inputs) = parts.inputs {
        spawn(spawner, input_task(inputs.part), "input");
        defmt::info!("inputs: {=str}", inputs.pins);
    }
    if let Some(uart) = parts.uart {
        spawn(
            spawner,
            console(ConsolePort::Uart(uart.part), parts.service),
            "uart console",
        );
        defmt::info!("console: UART {=str}, 115200 8N1", uart.pins);
    }
    if let Some(usb) = parts.usb {
        spawn_usb(spawner, usb, parts.service);
    }
}

/// What the boot leaves for the frame task and the console.
struct Head {
    driver: DriverParams,
    behaviour: BehaviourParams,
    service: &'static Service,
}

/// Runs the boot sequence on the settings `loaded` on the board `id` with
/// `parts`, spawns the loop generator and puts the console service in its
/// static.
#[inline(never)]
fn boot_head(
    spawner: Spawner,
    loaded: Loaded<flash::Storage>,
    id: BoardId,
    parts: BoardParts,
) -> Option<Head> {
    let Ok(booted) = boot::boot_on(&CONFIG, loaded, oscillator_jitter(), id, parts) else {
        defmt::error!("boot: called twice");
        return None;
    };
    spawn(spawner, generator(booted.generator), "generator");
    let service = &*SERVICE.init(Mutex::new(RefCell::new(booted.service)));
    Some(Head {
        driver: booted.driver,
        behaviour: booted.behaviour,
        service,
    })
}

/// Starts the frame task's executor and spawns the frame task on `servos`.
#[inline(never)]
fn spawn_frames(servos: [ServoPwm; 3], head: &Head, watchdog: BoardWatchdog) {
    let driver = FrameDriver::new(servos, head.driver);
    // The frame task's interrupt: above thread mode, below the time
    // driver's alarm (priority 0), which wakes it.
    interrupt::SWI_IRQ_1.set_priority(Priority::P1);
    let frames = FRAME_EXECUTOR.start(interrupt::SWI_IRQ_1);
    if let Ok(token) = frame_task(driver, head.behaviour, watchdog) {
        frames.spawn(token);
    } else {
        defmt::error!("frame task already running");
    }
}

/// Starts the DMX receiver.
#[inline(never)]
fn spawn_dmx(Wired { part: dmx, pins }: Wired<DmxUart>) {
    dmx::listen(dmx);
    let settings = LINKS.show.dmx.settings();
    defmt::info!(
        "dmx: {=str}, {=u32} baud 8N2, {=str}, address {=u16}",
        pins,
        dmx::BAUD,
        if settings.on { "on" } else { "off" },
        settings.address.get()
    );
}

/// Starts the radar's receiver, if set up.
#[inline(never)]
fn spawn_radar(Wired { part: radar, pins }: Wired<Option<RadarRx>>) {
    let Some(rx) = radar else {
        defmt::error!("radar: its receiver could not be set up ({=str})", pins);
        return;
    };
    radar::listen(rx);
    defmt::info!(
        "radar: {=str}, {=u32} baud 8N1, {=str}",
        pins,
        radar::BAUD,
        if LINKS.show.track.settings().radar {
            "on"
        } else {
            "off"
        }
    );
}

/// Logs the board's unique id, whose seeds the idle plays by default
/// (`seed board`).
fn log_id(id: BoardId) {
    if let Some(seed) = id.seed() {
        defmt::info!("board id {=u64:016x}: seed board:{=u32}", id.0, seed);
    } else {
        defmt::info!("board id: none read (seed board plays the paper's seeds)");
    }
}

/// Spawns the USB device and the console on its serial port.
#[inline(never)]
fn spawn_usb(
    spawner: Spawner,
    usb: embassy_rp::usb::Driver<'static, USB>,
    service: &'static Service,
) {
    let (device, serial) = usb::build(usb);
    spawn(spawner, usb_device(device), "usb device");
    spawn(
        spawner,
        console(ConsolePort::Usb(UsbPort(serial)), service),
        "usb console",
    );
    defmt::info!(
        "console: USB CDC-ACM {=u16:04x}:{=u16:04x}",
        usb::VID,
        usb::PID
    );
}

/// Spawns `token` on `spawner`, or logs that it could not.
fn spawn<S>(
    spawner: Spawner,
    token: Result<embassy_executor::SpawnToken<S>, embassy_executor::SpawnError>,
    name: &'static str,
) {
    if let Ok(token) = token {
        spawner.spawn(token);
    } else {
        defmt::error!("{=str} task already running", name);
    }
}

/// Logs the board, the servo outputs' clocking and the frame timing.
fn log_clocks(name: &str, servo_pins: &str) {
    let clock = SERVO_CLOCK;
    defmt::info!(
        "{=str}: servos {=str}; {=u32} Hz system clock, divider {=u8}+{=u8}/16, TOP {=u16}, {=u64} ps per count, period {=u64} ns",
        name,
        servo_pins,
        SYS_HZ,
        clock.divider_int(),
        clock.divider_frac(),
        clock.top,
        clock.count_ps(SYS_HZ),
        clock.period_ns(SYS_HZ)
    );
    let running = embassy_rp::clocks::clk_sys_freq();
    if running != SYS_HZ {
        defmt::error!(
            "system clock {=u32} Hz, not {=u32} Hz: the servo pulses are off by the same ratio",
            running,
            SYS_HZ
        );
    }
}

/// 32 bits from the ring oscillator's RANDOMBIT: its jitter against the
/// system clock, different on every boot and board. The ROSC keeps running
/// beside the crystal in embassy-rp's default clock configuration. Its bits
/// are not uniform, so 64 are folded into 32; the console's `seed random`
/// stirs them further.
fn oscillator_jitter() -> u32 {
    let bits = embassy_rp::clocks::RoscRng.next_u64();
    bits as u32 ^ (bits >> 32) as u32
}

/// The hardware watchdog: fed by the frame task after every frame, and by
/// the settings store before it holds the flash (and the interrupts) busy.
static WATCHDOG: Mutex<CriticalSectionRawMutex, RefCell<Option<RpWatchdog>>> =
    Mutex::new(RefCell::new(None));

/// Runs `f` on the hardware watchdog, once the boot has put it in place.
fn with_watchdog(f: impl FnOnce(&mut RpWatchdog)) {
    WATCHDOG.lock(|cell| {
        if let Ok(mut watchdog) = cell.try_borrow_mut()
            && let Some(watchdog) = watchdog.as_mut()
        {
            f(watchdog);
        }
    });
}

/// Feeds the hardware watchdog for `timeout` (the settings store's guard).
fn feed_watchdog(timeout: Duration) {
    with_watchdog(|watchdog| watchdog.feed(timeout));
}

/// The hardware watchdog, as the frame task's hooks use it.
struct BoardWatchdog;

impl Watchdog for BoardWatchdog {
    fn start(&mut self, timeout: Duration) {
        with_watchdog(|watchdog| watchdog.start(timeout));
    }

    fn feed(&mut self, timeout: Duration) {
        feed_watchdog(timeout);
    }
}

/// Bytes of stack used since reset: the stack region was painted before
/// `main` (cortex-m-rt's `paint-stack`), and the deepest write is the
/// lowest word that lost its paint.
fn peak_stack() -> u32 {
    cortex_m_stack::stack_size().saturating_sub(cortex_m_stack::stack_painted())
}

// The behaviour's parameters go to the task once, at boot.
#[allow(clippy::large_types_passed_by_value)]
#[embassy_executor::task]
async fn frame_task(
    mut driver: FrameDriver<ServoPwm>,
    behaviour: BehaviourParams,
    watchdog: BoardWatchdog,
) {
    let mut hooks = BoardHooks::new(watchdog, &FLASH_BUSY);
    // Loop set 0, from the generator: about 3 ms after boot.
    let (first, _) = LINKS.exchange.first().await;
    // Frames at the settings' rate, as the driver was built.
    let period = driver.params().config().frame_period;
    let (stats, _) =
        idle_head_firmware::tasks::play(&mut driver, first, &behaviour, &mut hooks, period, &LINKS)
            .await;
    // The hooks only stop in the watchdog drill; then the watchdog resets
    // the board.
    defmt::error!("frame task ended: {}", stats);
    // The drill stalls here, a hung frame task: the PWM keeps sending the
    // last pulse until the reset (returning would drop the driver, whose
    // slices switch off at once, mid-pulse).
    core::future::pending::<()>().await;
}

/// The status report, once a loop (thread mode: its stack scan and log
/// wait for everything else).
#[embassy_executor::task]
async fn report_task() {
    let playback = idle_head_firmware::tasks::playback();
    idle_head_firmware::report::run(
        playback.loop_duration(),
        peak_stack,
        waits::port_wait_us,
        &LINKS,
    )
    .await;
}

/// Generates loop set 0, then each next loop set while the frames play.
#[embassy_executor::task]
async fn generator(generator: Generator) {
    idle_head_firmware::tasks::generate(generator, Clock).await;
}

/// The trigger inputs, for as long as the board runs.
// ANCHOR: task
#[embassy_executor::task]
async fn input_task(mut inputs: GpioInputs) {
    idle_head_firmware::input::run(&mut inputs, &LINKS).await;
}
// ANCHOR_END: task

/// The USB device: enumeration, control requests, bus resets.
#[embassy_executor::task]
async fn usb_device(mut device: usb::Device) {
    device.run().await;
}

/// Where a console port is: its number, the link, the frame period.
const fn place(port: u8) -> idle_head_firmware::console::Place<'static> {
    idle_head_firmware::console::Place {
        port,
        link: &LINKS.console,
        frame: Duration::from_micros(CONFIG.frame_period.0 as u64),
    }
}

/// The console on a port (the UART is port 0, the USB serial port 1), for
/// as long as the board runs: one task, run twice, so that the console's
/// loop is in the image once ([`ConsolePort`]).
#[embassy_executor::task(pool_size = 2)]
async fn console(mut port: ConsolePort, service: &'static Service) {
    let (name, number) = match port {
        ConsolePort::Uart(_) => ("uart", 0),
        ConsolePort::Usb(_) => ("usb", 1),
    };
    idle_head_firmware::console::run(&mut port, service, name, place(number), &LINKS.show.curves)
        .await;
}

/// Either of the console's ports, as one type: the console's loop (the
/// session, Bottango, telemetry) is generic over its port, and one type
/// compiles it once instead of once a port (about 2.5 KB of flash).
enum ConsolePort {
    Uart(UartPort),
    Usb(UsbPort),
}

impl Port for ConsolePort {
    async fn connected(&mut self) {
        match self {
            Self::Uart(port) => port.connected().await,
            Self::Usb(port) => port.connected().await,
        }
    }

    fn open(&self) -> bool {
        match self {
            Self::Uart(port) => port.open(),
            Self::Usb(port) => port.open(),
        }
    }

    async fn read(&mut self, buf: &mut [u8]) -> Result<Received, Gone> {
        match self {
            Self::Uart(port) => port.read(buf).await,
            Self::Usb(port) => port.read(buf).await,
        }
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Gone> {
        match self {
            Self::Uart(port) => port.write(bytes).await,
            Self::Usb(port) => port.write(bytes).await,
        }
    }
}
