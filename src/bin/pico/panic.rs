//! The panic handler: the log says where the board stopped, then a hard
//! fault halts it (a debug probe shows the backtrace; the watchdog resets a
//! board running on its own).
//!
//! Only the location is logged, as `panicked at <file>:<line>`, not the
//! message: formatting it would link `core::fmt` into the image. The file
//! and line lead to the message in the source. (The messages themselves
//! and a few `core::fmt` pieces they point to, about 2 KB, stay in flash:
//! core builds them before the handler runs.)

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicBool, Ordering};

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    // Set once the first panic has been logged: a panic inside the logger
    // itself then halts at once instead of recursing.
    static PANICKED: AtomicBool = AtomicBool::new(false);

    cortex_m::interrupt::disable();
    if !PANICKED.load(Ordering::Relaxed) {
        PANICKED.store(true, Ordering::Relaxed);
        match info.location() {
            Some(at) => defmt::error!("panicked at {=str}:{=u32}", at.file(), at.line()),
            None => defmt::error!("panicked"),
        }
    }
    // ARMv6-M has no usage fault: `udf` is a hard fault, where a debug
    // probe (probe-rs) stops and prints the backtrace.
    cortex_m::asm::udf()
}
