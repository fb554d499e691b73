//! Ending the QEMU run: semihosting exit codes, the panic and HardFault
//! handlers.
//!
//! Both handlers log one complete defmt frame, then leave QEMU with a non-zero
//! exit status. A fault raised *while* a defmt frame is being written (the
//! logger is taken) makes the logging attempt panic again; that nested panic
//! exits at once without writing, so the host decoder sees at worst one
//! truncated frame, which the rzCOBS framing lets it skip.

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{ExceptionFrame, exception};
use cortex_m_semihosting::debug;

/// Set by the first panic; a second one exits without logging.
static PANICKED: AtomicBool = AtomicBool::new(false);

/// Leaves QEMU with exit status 0 (`true`) or 1 (`false`).
pub fn exit(success: bool) -> ! {
    debug::exit(if success {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    // Only reached without a semihosting host (e.g. on real hardware).
    loop {
        cortex_m::asm::bkpt();
    }
}

#[panic_handler]
fn panic(info: &PanicInfo<'_>) -> ! {
    cortex_m::interrupt::disable();
    // thumbv6m has no atomic swap; interrupts are off, so load + store is one
    // step for everything but a fault inside this handler, which is the case
    // being guarded against.
    if !PANICKED.load(Ordering::Relaxed) {
        PANICKED.store(true, Ordering::Relaxed);
        defmt::error!("panic: {}", defmt::Display2Format(info));
    }
    exit(false)
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    if !PANICKED.load(Ordering::Relaxed) {
        PANICKED.store(true, Ordering::Relaxed);
        defmt::error!(
            "HardFault: pc={=u32:#010x} lr={=u32:#010x} xpsr={=u32:#010x}",
            frame.pc(),
            frame.lr(),
            frame.xpsr()
        );
    }
    exit(false)
}
