//! The status report of a board running on its own: once a loop, the
//! frames written, their latest wake-up, the faults, the peak stack and the
//! longest wait of a port task.
//!
//! It runs in thread mode, below every other task: the stack scan (it reads
//! the unused stack, a few hundred microseconds) and the log wait for the
//! frames, the console, the inputs and the loop generator.

use core::sync::atomic::Ordering;

use embassy_time::{Duration, Ticker};
use idle_head_core::Millis;

use crate::boot::LINK;
use crate::frame::LATEST_WAKE_US;

/// Logs a report every `every` (a loop), with the board's `peak_stack`
/// (bytes) and `port_wait` (µs) measures. Never returns.
pub async fn run(every: Millis, peak_stack: fn() -> u32, port_wait: fn() -> u32) -> ! {
    let mut ticker = Ticker::every(Duration::from_millis(u64::from(every.0.max(1))));
    let mut loops: u32 = 0;
    loop {
        ticker.next().await;
        loops = loops.wrapping_add(1);
        let status = LINK.status();
        defmt::info!(
            "loop {=u32} done: {=u64} frames written, wake-up at most {=u32} us late, faults {}, disabled {}, peak stack {=u32} B, port tasks waited at most {=u32} us",
            loops,
            status.frame,
            LATEST_WAKE_US.load(Ordering::Relaxed),
            status.faults,
            status.disabled,
            peak_stack(),
            port_wait()
        );
    }
}
