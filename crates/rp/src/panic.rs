//! The panic handler: the log says that the board stopped on a panic, then
//! a hard fault halts it (the watchdog resets a board running on its own).
//!
//! The log line names no place: where the panic happened is told by the
//! debug probe, not by the image. `probe-rs run` (the runner of `cargo run
//! --release`) stops the core on the hard fault and prints the backtrace,
//! every frame with its file and line taken from the ELF's debug
//! information, down to the panic site. The log itself travels over RTT,
//! through that same probe, so a location in it would show nothing the
//! backtrace does not. Reading neither the location nor the message lets
//! the link drop every panic site's file path and message: 10 KB of the
//! console image's flash, 4 KB of the default image's.

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicBool, Ordering};

#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    // Set once the first panic has been logged: a panic inside the logger
    // itself then halts at once instead of recursing.
    static PANICKED: AtomicBool = AtomicBool::new(false);

    cortex_m::interrupt::disable();
    if !PANICKED.load(Ordering::Relaxed) {
        PANICKED.store(true, Ordering::Relaxed);
        defmt::error!("panic: halted (the probe's backtrace shows where)");
    }
    // ARMv6-M has no usage fault: `udf` is a hard fault, where `probe-rs
    // run` stops and prints the backtrace.
    cortex_m::asm::udf()
}
