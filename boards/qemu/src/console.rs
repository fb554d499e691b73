//! The console task of the QEMU image: the firmware's console loop
//! ([`idle_head_firmware::console::serve`]) over UART0, settings kept in
//! RAM; UART1 is the hang-up line.
//!
//! The semihosting command line says what kind of run this is
//! ([`Mode::from_host`]):
//!
//! - nothing: the smoke run (`cargo xtask qemu`): the script, the injected
//!   faults and the checks, at 20 times real time, ending on its schedule;
//!   the console answers whatever arrives;
//! - `console`: the smoke run *held* for its console (the telemetry check
//!   of `cargo xtask bench`): its fade-out waits until the host hangs up,
//!   which it signals with any byte on UART1 (as a modem's DTR line would);
//! - `interactive`: a clean head for a person (`cargo xtask console
//!   --qemu`, `cargo xtask panel --qemu`): no script, no injected fault,
//!   frames at the board's real 20 ms, and no end but the hang-up. `stop`
//!   holds the head at its neutral pose until a motion command wakes it,
//!   as on a board.

use core::future::Future;
use core::pin::Pin;
use core::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use core::task::{Context, Poll};

use embassy_time::Duration;
use idle_head_core::console::{BoardParts, ConsoleService, DualSession};
use idle_head_core::input::InputIds;
use idle_head_core::seed::BoardId;
use idle_head_core::settings::RamStorage;
use idle_head_firmware::boot::{self, BootError, Booted, LINKS, Loaded};
use idle_head_firmware::console::{Gone, Place, Port, Received, serve};

use crate::uart::{RX_READY, UART0, UART1};

/// What the console answers for: the Pico's inputs (`input 2` to
/// `input 5`), DMX and the radar, so that a host tool (the panel,
/// `cargo xtask console --qemu`) meets the Pico's console. Nothing is
/// wired to them here: the inputs never change, DMX is `lost`, the radar
/// sees nobody.
pub const PARTS: BoardParts = BoardParts {
    inputs: match InputIds::new(&[2, 3, 4, 5]) {
        Ok(ids) => ids,
        Err(_) => InputIds::NONE,
    },
    dmx: true,
    radar: true,
};

/// The boot sequence on the built-in settings, saved to RAM, with the
/// console answering for [`PARTS`].
pub fn boot() -> Result<Booted<RamStorage>, BootError> {
    let loaded = Loaded::defaults(RamStorage::new());
    boot::boot_on(&crate::CONFIG, loaded, 0, BoardId::NONE, PARTS)
}

/// What kind of run this is; see the [module docs](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Mode {
    /// The smoke run, on its schedule.
    Smoke,
    /// The smoke run, its fade-out held until the host hangs up.
    Held,
    /// A clean head at real time, until the host hangs up.
    Interactive,
}

impl Mode {
    /// The mode the semihosting command line asks for: the word
    /// `interactive` or `console` in it, or neither.
    pub fn from_host() -> Self {
        let mut buf = [0_u8; 64];
        let mut block = [buf.as_mut_ptr() as usize, buf.len()];
        // Note(unsafe): SYS_GET_CMDLINE writes at most `block[1]` bytes into
        // `buf` and the length used into `block[1]`; both outlive the call.
        let status = unsafe {
            cortex_m_semihosting::syscall1(
                cortex_m_semihosting::nr::GET_CMDLINE,
                block.as_mut_ptr() as usize,
            )
        };
        let len = block[1].min(buf.len());
        let mut words = buf[..len].split(|b| *b == b' ' || *b == 0);
        if status != 0 {
            Self::Smoke
        } else if words.clone().any(|word| word == b"interactive") {
            Self::Interactive
        } else if words.any(|word| word == b"console") {
            Self::Held
        } else {
            Self::Smoke
        }
    }

    /// Whether the run lasts until the host hangs up.
    pub const fn held(self) -> bool {
        !matches!(self, Self::Smoke)
    }
}

/// The run's [`Mode`], as an index (set once by `main`).
static MODE: AtomicU8 = AtomicU8::new(0);

/// Sets the run's mode.
pub fn set_mode(mode: Mode) {
    MODE.store(mode as u8, Ordering::Relaxed);
}

/// The run's mode.
pub fn mode() -> Mode {
    match MODE.load(Ordering::Relaxed) {
        1 => Mode::Held,
        2 => Mode::Interactive,
        _ => Mode::Smoke,
    }
}

/// Set once the host has hung up and every queued command was played.
pub static HUNG_UP: AtomicBool = AtomicBool::new(false);

/// The service as the QEMU image runs it.
pub type Service = ConsoleService<'static, RamStorage>;

/// UART0 as a console port; a byte on UART1 (the host hanging up) makes
/// it go away.
struct Uart0;

impl Port for Uart0 {
    async fn read(&mut self, buf: &mut [u8]) -> Result<Received, Gone> {
        loop {
            if UART1.read().is_some() {
                return Err(Gone);
            }
            if UART0.pending() {
                // Let the loop generator (same executor) run between reads,
                // before any byte is taken: a read dropped here (`serve`'s
                // telemetry tick came first) has taken none, as `Port::read`
                // requires, and no await follows the taking.
                YieldNow(false).await;
                let mut n = 0;
                while let Some(slot) = buf.get_mut(n) {
                    let Some(byte) = UART0.read() else { break };
                    *slot = byte;
                    n += 1;
                }
                return Ok(Received::Bytes(n));
            }
            UART0.listen();
            UART1.listen();
            RX_READY.wait().await;
        }
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Gone> {
        UART0.write_all(bytes);
        Ok(())
    }
}

/// Answers the lines on UART0 until the host hangs up, then lets the
/// queued commands play and says so ([`HUNG_UP`]).
#[embassy_executor::task]
pub async fn console(mut service: Service, frame: Duration) {
    UART0.init();
    UART1.init();
    // No Bottango here: the QEMU image has no show layer's curves to play.
    let mut session = DualSession::new(None);
    let place = Place {
        port: 0,
        link: &LINKS.console,
        frame,
    };
    let Gone = serve(&mut Uart0, &mut session, &mut service, place).await;
    defmt::info!(
        "console: the host hung up at frame {=u64}",
        LINKS.console.status().frame
    );
    // The queued commands are played before the run ends.
    while !LINKS.commands.is_empty() || LINKS.console.servos_pending() {
        YieldNow(false).await;
    }
    HUNG_UP.store(true, Ordering::Release);
}

/// Pending once, then ready: gives the other tasks of the executor a turn.
struct YieldNow(bool);

impl Future for YieldNow {
    type Output = ();

    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<()> {
        if self.0 {
            Poll::Ready(())
        } else {
            self.0 = true;
            cx.waker().wake_by_ref();
            Poll::Pending
        }
    }
}
