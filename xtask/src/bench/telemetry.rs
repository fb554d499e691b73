//! The frame work with telemetry streaming: `watch 50` on the QEMU image's
//! UART0 through the smoke schedule must leave the frame work the smoke run
//! logs (average and worst) within one `SysTick` count of the run without
//! it: telemetry is written by the console task, never on the frame path.

use std::{
    io::Read,
    path::Path,
    sync::atomic::{AtomicUsize, Ordering},
    time::{Duration, Instant},
};

use anyhow::{Context, Result, bail};

use crate::console::{Pace, qemu_session};
use crate::log::{LogLine, Run};
use crate::qemu::{self, Echo};

/// Instructions per `SysTick` count in the smoke run (12.5 MHz after reset
/// under `-icount shift=0`, `boards/qemu/src/systick.rs`).
const INSNS_PER_COUNT: u64 = 80;

/// Telemetry lines to see before the host hangs up: the schedule's
/// fade-out starts at frame 1800, a line every 20 frames.
const LINES: usize = 80;

/// The console's input: `watch 50`, then nothing until [`LINES`] telemetry
/// lines came (or the deadline passed), then the end (the host hangs up).
struct Streaming<'a> {
    sent: bool,
    seen: &'a AtomicUsize,
    deadline: Instant,
}

impl Read for Streaming<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if !std::mem::replace(&mut self.sent, true) {
            let line = b"watch 50\n";
            buf[..line.len()].copy_from_slice(line);
            return Ok(line.len());
        }
        while self.seen.load(Ordering::Acquire) < LINES && Instant::now() < self.deadline {
            std::thread::sleep(Duration::from_millis(5));
        }
        Ok(0)
    }
}

/// What a run logged of its frame work: `(average, at most)`.
fn frame_work(log: &[LogLine]) -> Result<(u64, u64)> {
    let line = log
        .iter()
        .find_map(|l| l.message.strip_prefix("frame work: "));
    let line = line.context("the run logged no frame work")?;
    let words = line.split(|c: char| !c.is_ascii_digit());
    let mut numbers = words.filter(|w| !w.is_empty()).map(str::parse);
    match (numbers.next(), numbers.next()) {
        (Some(Ok(average)), Some(Ok(most))) => Ok((average, most)),
        _ => bail!("unreadable frame work line: {line}"),
    }
}

/// Runs the QEMU smoke image `elf` with `watch 50` streaming, against its
/// plain run (`plain`, else run here): the bench's line about it, or why
/// the frames were not untouched.
pub fn check(elf: &Path, timeout: Duration, plain: Option<&Run>) -> Result<String> {
    let without = match plain {
        Some(run) => frame_work(&run.log)?,
        None => frame_work(&qemu::run(elf, timeout, Echo::Problems)?.log)?,
    };
    let seen = AtomicUsize::new(0);
    let input = Streaming {
        sent: false,
        seen: &seen,
        deadline: Instant::now() + timeout,
    };
    let mut count = |line: &[u8]| {
        if line.starts_with(b"~ ") {
            seen.fetch_add(1, Ordering::AcqRel);
        }
    };
    let wait = Duration::from_secs(5);
    let session = qemu_session(elf, input, &mut count, Pace::Fast, Echo::Problems, wait)?;
    let lines = seen.load(Ordering::Acquire);
    let with = frame_work(&session.run.log)?;
    let verdict = qemu::check_summary(&session.run.log)?;
    if lines < LINES {
        bail!("telemetry: only {lines} lines streamed during the run");
    }
    let line = format!(
        "telemetry: the smoke schedule with `watch 50` streaming on UART0 ({lines} lines): \
         frame work {} instructions on average, at most {} (without: {}, {}); {verdict}",
        with.0, with.1, without.0, without.1
    );
    let count = INSNS_PER_COUNT;
    if with.0.abs_diff(without.0) > count || with.1.abs_diff(without.1) > count {
        bail!(
            "{line}: telemetry changed the frame work by more than one count ({count} instructions)"
        );
    }
    Ok(format!(
        "{line}\ntelemetry adds nothing to the frame path (within one count of {count} \
         instructions): it is written by the console task, and the frame rows above hold with \
         `watch 50` running"
    ))
}
