//! Every latency path ([`PATHS`]) and the stage that runs them all; here
//! the console's ports and Bottango, in `latency.rs` the method, the rows,
//! DMX and the input edge.

// Times in ns of virtual time, far below 2^52, and positive.
#![allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]

use std::{path::Path, time::Duration};

use anyhow::{Context, Result, bail};
use idle_head_core::servo::ServoRate;

use super::latency::{self, LOOK_GAP, Row, SCHEDULED, Shipped, count, first_boot, schedule};
use crate::project::Metadata;
use crate::sim::{BYTE_TIME, Boot, Chunk, UartScript, bottango_lines, run_shipped};
use crate::{figures, project};

/// A path's run, for its row.
pub type Measure = fn(&Path, &Metadata, Duration) -> Result<Row>;

/// Every latency path, in the order the bench prints them.
pub const PATHS: [Measure; 6] = [
    latency::dmx,
    usb_look,
    uart_look,
    latency::input_edge,
    bottango,
    uart_look_200_hz,
];

/// The `look` events' lines: with the idle off, yaw a degree there and back.
fn look_line(k: usize) -> Vec<u8> {
    let yaw = if k.is_multiple_of(2) { 1000 } else { 0 };
    format!("look 0 {yaw} 40 hold=stay\n").into_bytes()
}

/// Fails if a line of `replies` refused its line (`err …`, or Bottango's
/// `HASH_FAIL` and `TIMEOUT`).
fn all_ok(replies: &[u8], what: &str) -> Result<()> {
    let text = String::from_utf8_lossy(replies);
    let refused = |l: &&str| l.starts_with("err") || l.contains("FAIL") || l.contains("TIMEOUT");
    match text.lines().find(refused) {
        Some(line) => bail!("{what}: a line refused: {line:?}"),
        None => Ok(()),
    }
}

/// [`first_boot`] with `chunks` sent to the USB port, every reply `ok`.
fn usb_run(run: Shipped, times: &[Duration], chunks: Vec<Chunk>, what: &str) -> Result<Boot> {
    let boot = first_boot(run, times, |config| config.usb = chunks)?;
    all_ok(&boot.usb, what)?;
    Ok(boot)
}

/// `latency usb look`: `look` lines over USB.
pub fn usb_look(root: &Path, metadata: &Metadata, wall: Duration) -> Result<Row> {
    let times = schedule(Duration::from_secs(4), SCHEDULED, LOOK_GAP, 0x1007_c0de);
    let mut chunks = vec![Chunk::new(b"idle off\n", Duration::from_millis(2500))];
    let looks = times.iter().enumerate();
    chunks.extend(looks.map(|(k, at)| Chunk::new(look_line(k), *at)));
    let boot = usb_run((root, metadata, wall), &times, chunks, "usb look")?;
    let events: Vec<f64> = boot.usb_in.iter().skip(1).copied().collect();
    count(events.len(), times.len(), "USB lines went out")?;
    latency::row("usb look", &events, &boot)
}

/// `latency uart look`: `look` lines over UART0 at 115200 baud, each in by
/// its time.
pub fn uart_look(root: &Path, metadata: &Metadata, wall: Duration) -> Result<Row> {
    let (events, boot) = uart_looks((root, metadata, wall), b"idle off\n", 0x0a47_100c)?;
    latency::row("uart look", &events, &boot)
}

/// `latency uart look at 200 Hz`: the same after `servo rate 200`, against
/// its own goal (a 5 ms frame and the transport).
pub fn uart_look_200_hz(root: &Path, metadata: &Metadata, wall: Duration) -> Result<Row> {
    let setup = b"idle off\nservo rate 200\n";
    let (events, boot) = uart_looks((root, metadata, wall), setup, 0x200_100c)?;
    let answered = String::from_utf8_lossy(&boot.uart);
    let taken = |line: &str| line.trim_end() == "ok servo rate=200 period_us=5000";
    if !answered.lines().take(2).any(taken) {
        let start = String::from_utf8_lossy(&boot.uart[..boot.uart.len().min(80)]);
        bail!("uart look at 200 Hz: the rate was not taken: {start:?}");
    }
    let rate = ServoRate::new(200).context("200 Hz is a servo rate")?;
    let goal = latency::GOAL_200_HZ_MS;
    latency::row_at("uart look at 200 Hz", &events, &boot, rate, goal)
}

/// A run of `look` lines over UART0 at times seeded by `seed` after `setup`
/// (one or more lines, at 2.5 s): each line's arrival, and the boot, every
/// line answered `ok`.
fn uart_looks(run: Shipped, setup: &[u8], seed: u32) -> Result<(Vec<f64>, Boot)> {
    let times = schedule(Duration::from_secs(4), SCHEDULED, LOOK_GAP, seed);
    let mut scripts = vec![UartScript::new(0, setup, Duration::from_millis(2500))];
    scripts.extend(times.iter().enumerate().map(|(k, &at)| {
        let line = look_line(k);
        let on_the_wire = BYTE_TIME * u32::try_from(line.len()).unwrap_or(u32::MAX);
        UartScript::new(0, line, at.saturating_sub(on_the_wire))
    }));
    let boot = first_boot(run, &times, |config| config.uart = scripts)?;
    // One script for the setup, one for each look.
    let (sent, want) = (boot.uart_lines.len(), times.len() + 1);
    count(sent, want, "UART scripts went out")?;
    all_ok(&boot.uart, "uart look")?;
    Ok((boot.uart_lines.iter().skip(1).copied().collect(), boot))
}

/// The gaps between Bottango's curves: a 40 ms step, then a hold.
const CURVE_GAP: (Duration, Duration) = (Duration::from_millis(150), Duration::from_millis(200));
/// How long before its start a curve is sent (Bottango sends ahead).
const AHEAD: Duration = Duration::from_millis(120);
/// The step, in Bottango's movement (0 to 8192 over the motor's range,
/// −20° to 20°): 256 is 1.25°.
const STEP: i32 = 256;

/// `latency bottango`: a Bottango session over USB steps yaw by 1.25° and
/// holds it, curve after curve, each sent ahead of its start; each step's
/// start (on the head's clock, which `tSYN` ties to a frame) against yaw's
/// first pulse that moves.
pub fn bottango(root: &Path, metadata: &Metadata, wall: Duration) -> Result<Row> {
    // When the first frame goes out: the head's clock counts from it.
    let first = run_shipped(root, metadata, Duration::from_secs(1), wall, |_| {})?;
    let t0 = first.first()?.trains[2].enabled.context("no first frame")?;
    let frame = crate::sim::run::timing().frame_ns;
    // The sync in the middle of a frame after 2.6 s: the clock it marks is
    // the frame before, whatever the line's few µs of transport.
    let k = ((2.6e9 - t0) / frame).ceil();
    let sync = Duration::from_nanos((t0 + (k + 0.5) * frame) as u64);
    let clock_ms = (k * frame / 1e6).round() as u64;
    // The curves' starts, whole ms after the sync's clock.
    let after = Duration::from_secs(4);
    let times = schedule(after, SCHEDULED + 1, CURVE_GAP, 0xb077_a160);
    let ms_after = |at: Duration| ((at.as_secs_f64() * 1e9 - t0) / 1e6).round() as u64 - clock_ms;
    let setup = bottango_lines(&["hRQ,144", "rMTR,yaw,-20000,20000,3000,4096"]).concat();
    let mut chunks = vec![
        Chunk::new(b"idle off\n", Duration::from_secs(2)),
        Chunk::new(setup, Duration::from_millis(2300)),
        Chunk::new(bottango_lines(&["tSYN,0"]).concat(), sync),
    ];
    let mut events = Vec::new();
    for (i, pair) in times.windows(2).enumerate() {
        let (start, next) = (ms_after(pair[0]), ms_after(pair[1]));
        let (from, to) = [(4096, 4096 + STEP), (4096 + STEP, 4096)][i % 2];
        let step = format!("sC,yaw,{start},40,{from},0,{},{to},0,0", to - from);
        let (at, ms) = (start + 40, next - start - 40);
        let hold = format!("sC,yaw,{at},{ms},{to},0,0,{to},0,0");
        let lines = bottango_lines(&[&step, &hold]).concat();
        chunks.push(Chunk::new(lines, pair[0].saturating_sub(AHEAD)));
        events.push(t0 + (clock_ms + start) as f64 * 1e6);
    }
    let boot = usb_run((root, metadata, wall), &times, chunks, "bottango")?;
    latency::row("bottango", &events, &boot)
}

/// `job` of 0 to `count` − 1, `cores` at a time, in order; a job that
/// panicked is an error.
fn parallel<T: Send>(
    count: usize,
    cores: usize,
    job: impl Fn(usize) -> Result<T> + Sync,
) -> Vec<Result<T>> {
    let mut results = Vec::new();
    for batch in (0..count).collect::<Vec<_>>().chunks(cores.max(1)) {
        std::thread::scope(|scope| {
            let job = &job;
            let runs: Vec<_> = batch.iter().map(|&i| scope.spawn(move || job(i))).collect();
            let panicked = || Err(anyhow::anyhow!("a worker thread panicked"));
            results.extend(
                runs.into_iter()
                    .map(|run| run.join().unwrap_or_else(|_| panicked())),
            );
        });
    }
    results
}

/// Every latency row, printed and recorded; fails if a row misses its goal
/// (or could not be measured). The runs are independent emulators: as many
/// at once as there are cores.
pub fn stage(root: &Path, metadata: &Metadata) -> Result<()> {
    // One at a time when `cargo xtask test` runs it beside other stages.
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    let cores = if crate::project::prebuilt() { 1 } else { cores };
    let results = parallel(PATHS.len(), cores, |i| {
        PATHS[i](root, metadata, crate::sim::WALL)
    });
    let (mut rows, mut misses) = (Vec::new(), Vec::new());
    for result in results {
        match result {
            Ok(row) => {
                print!("{}", row.lines());
                rows.push(row.figure());
                misses.extend(row.misses());
            }
            Err(error) => misses.push(format!("{error:#}")),
        }
    }
    let intro = "Latency, measured in the RP2040 emulator on the shipped image, from an event \
                 to the first servo pulse that shows it, in ms \
                 ([the emulators](../dev/emulators.md#latency-of-an-input-edge)).";
    let wait = "longest wait of a port task for the CPU";
    let header = ["row", "events", "p50", "p99", "max", "goal (p99)", wait];
    figures::record("latency", intro.to_owned(), &header, rows);
    project::verdict(&misses)
}
