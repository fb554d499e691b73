//! The status report of a board running on its own: once a loop, the
//! frames written, their latest wake-up, the faults, the peak stack and the
//! longest wait of a port task; and whenever that wait grows, at once (a
//! second at the latest), so that the log always holds the longest.
//!
//! It runs in thread mode, below every other task: the stack scan (it reads
//! the unused stack, a few hundred microseconds) and the log wait for the
//! frames, the console, the inputs and the loop generator.

use core::sync::atomic::Ordering;

use embassy_time::{Duration, Ticker};
use idle_head_core::Millis;

use crate::boot::Links;
use crate::log;

/// How often the report looks at the port tasks' longest wait.
const LOOK: Duration = Duration::from_secs(1);

/// Logs a report every `every` (a loop), with the board's `peak_stack`
/// (bytes) and `port_wait` (µs) measures and the head's status from
/// `links`, and the port wait whenever it grows. Never returns.
pub async fn run(
    every: Millis,
    peak_stack: fn() -> u32,
    port_wait: fn() -> u32,
    links: &Links,
) -> ! {
    let looks_per_loop = (u64::from(every.0) / LOOK.as_millis()).max(1);
    let mut ticker = Ticker::every(LOOK);
    let (mut seconds, mut loops): (u64, u32) = (0, 0);
    // (None: not logged yet; the first look logs it whatever it is.)
    let mut waited: Option<u32> = None;
    loop {
        ticker.next().await;
        seconds += 1;
        let wait = port_wait();
        if waited.is_none_or(|w| wait > w) {
            waited = Some(wait);
            log::info!("port tasks waited at most {=u32} us", wait);
        }
        if seconds % looks_per_loop != 0 {
            continue;
        }
        loops = loops.wrapping_add(1);
        let status = links.console.status();
        log::info!(
            "loop {=u32} done: {=u64} frames written, wake-up at most {=u32} us late, faults {}, disabled {}, peak stack {=u32} B",
            loops,
            status.frame,
            links.latest_wake_us.load(Ordering::Relaxed),
            status.faults,
            status.disabled,
            peak_stack(),
        );
    }
}
