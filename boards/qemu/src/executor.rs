//! The QEMU image's two executors, as on the Pico: the frame task runs in a
//! raw embassy executor polled from interrupt 0 (GPIO port A on the
//! LM3S6965, unused here; cortex-m-rt's default vector table sends it to
//! `DefaultHandler`), above the thread-mode executor of `main`, where the
//! loop generator and the console run. The pender pends interrupt 0 for the
//! one and wakes the other from `WFI`.

use core::ptr;
use core::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use cortex_m_rt::exception;
use embassy_executor::raw;

use crate::{exit, uart};

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

/// The two executors: thread mode's and the frame interrupt's. `None` if
/// taken already.
pub fn take() -> Option<(&'static raw::Executor, &'static raw::Executor)> {
    let thread = cortex_m::singleton!(: raw::Executor = raw::Executor::new(usize::MAX as *mut ()))?;
    let frames =
        cortex_m::singleton!(: raw::Executor = raw::Executor::new(FRAME_CONTEXT as *mut ()))?;
    Some((thread, frames))
}

/// Unmasks the frame and UART interrupts and runs the thread-mode executor
/// for ever, sleeping whenever no task is woken.
pub fn run(
    nvic: &mut NVIC,
    thread: &'static raw::Executor,
    frame_executor: &'static raw::Executor,
) -> ! {
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
            nvic.set_priority(UartIrq(irq), 0x80);
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
