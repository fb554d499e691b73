//! How long the port tasks wait for the CPU: from the moment something
//! wakes one (its interrupt, a timer, another task) to the moment the port
//! executor polls it, the longest since boot ([`port_wait_us`]).
//!
//! Measured with embassy-executor's trace hooks, which the executors call
//! at every wake and poll of every task: a task's wake time is kept until
//! it is polled; a poll that runs in the port executor's interrupt
//! (`SWI_IRQ_0`) is a port task's. A task's first poll is no wake: at boot
//! the task that spawns the others runs to its end before they start.
//! The port executor is known by its first poll; the hooks of the other
//! executors (the frame task's among them) return at once from then on.

use core::cell::Cell;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::SCB;
use cortex_m::peripheral::scb::VectActive;
use embassy_rp::pac::Interrupt;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_time::Instant;

/// Tasks woken and not yet polled, at most: every task of the image.
const TASKS: usize = 8;

/// The tasks woken and not yet polled, with their wake time (µs), and the
/// longest port wait so far (µs).
struct Waits {
    woken: [Cell<Option<(u32, u64)>>; TASKS],
    /// The tasks polled once already.
    started: [Cell<Option<u32>>; TASKS],
    longest: Cell<u32>,
}

static WAITS: Mutex<CriticalSectionRawMutex, Waits> = Mutex::new(Waits {
    woken: [const { Cell::new(None) }; TASKS],
    started: [const { Cell::new(None) }; TASKS],
    longest: Cell::new(0),
});

/// The port executor's id, once it polled a task (0 before).
static PORT_EXECUTOR: AtomicU32 = AtomicU32::new(0);

/// The longest a port task waited for the CPU since boot, µs.
#[must_use]
pub fn port_wait_us() -> u32 {
    WAITS.lock(|w| w.longest.get())
}

/// Whether the code runs in the port executor's interrupt.
fn in_port_executor() -> bool {
    matches!(SCB::vect_active(), VectActive::Interrupt { irqn } if irqn == Interrupt::SWI_IRQ_0 as u8)
}

#[unsafe(no_mangle)]
extern "Rust" fn _embassy_trace_task_ready_begin(executor_id: u32, task_id: u32) {
    if executor_id != PORT_EXECUTOR.load(Ordering::Relaxed) {
        return;
    }
    let now = Instant::now().as_micros();
    WAITS.lock(|w| {
        // Woken again before its poll: the first wake counts.
        if w.woken
            .iter()
            .any(|slot| slot.get().is_some_and(|(id, _)| id == task_id))
        {
            return;
        }
        if let Some(slot) = w.woken.iter().find(|slot| slot.get().is_none()) {
            slot.set(Some((task_id, now)));
        }
    });
}

#[unsafe(no_mangle)]
extern "Rust" fn _embassy_trace_task_exec_begin(executor_id: u32, task_id: u32) {
    let port = PORT_EXECUTOR.load(Ordering::Relaxed);
    if port == 0 && in_port_executor() {
        PORT_EXECUTOR.store(executor_id, Ordering::Relaxed);
    } else if executor_id != port {
        return;
    }
    let now = Instant::now().as_micros();
    WAITS.lock(|w| {
        let first = !w.started.iter().any(|s| s.get() == Some(task_id));
        if first && let Some(free) = w.started.iter().find(|s| s.get().is_none()) {
            free.set(Some(task_id));
        }
        let Some(slot) = w
            .woken
            .iter()
            .find(|slot| slot.get().is_some_and(|(id, _)| id == task_id))
        else {
            return;
        };
        if let (Some((_, woken)), false) = (slot.take(), first) {
            let waited = u32::try_from(now.saturating_sub(woken)).unwrap_or(u32::MAX);
            w.longest.set(w.longest.get().max(waited));
        }
    });
}

#[unsafe(no_mangle)]
extern "Rust" fn _embassy_trace_task_exec_end(_executor_id: u32, _task_id: u32) {}

#[unsafe(no_mangle)]
extern "Rust" fn _embassy_trace_task_new(_executor_id: u32, _task_id: u32) {}

#[unsafe(no_mangle)]
extern "Rust" fn _embassy_trace_task_end(_executor_id: u32, _task_id: u32) {}

#[unsafe(no_mangle)]
extern "Rust" fn _embassy_trace_poll_start(_executor_id: u32) {}

#[unsafe(no_mangle)]
extern "Rust" fn _embassy_trace_executor_idle(_executor_id: u32) {}
