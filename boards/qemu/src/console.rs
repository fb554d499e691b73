//! The console task of the QEMU image: the core's console service over
//! UART0, settings kept in RAM.
//!
//! With `console` on the semihosting command line (`cargo xtask console
//! --qemu`, and the flood stage of `cargo xtask test`) the run is *held*:
//! the smoke schedule plays as usual, but the fade-out that ends it waits
//! until the host hangs up, which it signals with any byte on UART1 (as a
//! modem's DTR line would). Without it (`cargo xtask qemu`) the run ends
//! on its schedule; the console still answers whatever arrives.

use core::future::Future;
use core::pin::Pin;
use core::sync::atomic::{AtomicBool, Ordering};
use core::task::{Context, Poll};

use idle_head_core::console::{ConsoleService, Session};
use idle_head_core::settings::RamStorage;
use idle_head_firmware::boot::{COMMANDS as QUEUE, LINK};

use crate::uart::{RX_READY, UART0, UART1};

/// Whether the run waits for the host to hang up.
pub static HOLD: AtomicBool = AtomicBool::new(false);
/// Set once the host has hung up and every queued command was played.
pub static HUNG_UP: AtomicBool = AtomicBool::new(false);

/// The service as the QEMU image runs it.
pub type Service = ConsoleService<'static, RamStorage>;

/// Whether the semihosting command line holds the word `console`.
pub fn held_by_host() -> bool {
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
    status == 0
        && buf[..len]
            .split(|b| *b == b' ' || *b == 0)
            .any(|word| word == b"console")
}

/// Reads lines from UART0, answers each, until the host hangs up.
#[embassy_executor::task]
pub async fn console(mut service: Service) {
    UART0.init();
    UART1.init();
    let mut session = Session::<96, 160>::new();
    let mut lines: u32 = 0;
    loop {
        while let Some(byte) = UART0.read() {
            if let Some(reply) = session.push(byte, &mut service) {
                UART0.write_all(reply);
                lines = lines.wrapping_add(1);
                // Let the loop generator (same executor) run between lines.
                YieldNow(false).await;
            }
        }
        if UART1.read().is_some() {
            break;
        }
        UART0.listen();
        UART1.listen();
        RX_READY.wait().await;
    }
    defmt::info!(
        "console: the host hung up after {=u32} lines, at frame {=u64}",
        lines,
        LINK.status().frame
    );
    // The queued commands are played before the run fades out.
    while !QUEUE.is_empty() || LINK.servos_pending() {
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
