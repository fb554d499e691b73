//! Lines streamed into the shipped image in the emulator, on UART0 (115200
//! 8N1, no flow control) or the USB serial port: one every 2 ms for ten
//! minutes of emulated time, across twenty loop generations, and none lost.
//!
//! The lines cycle through what a show controller sends between its moves:
//! two actions a frame (`center` and `idle on`, queued for the frame task
//! and answered once a frame has taken them; they leave the motion as it
//! is), settings (`watch off`) and machine-mode lines with their sequence
//! numbers (`#<n> watch off *<crc>`). Each line fits the 2 ms the UART takes
//! to carry 23 bytes, and the replies of a cycle fit the time its lines
//! take: the head can keep up, so whatever it loses is its own doing.
//!
//! The check:
//! - every line got exactly one reply, in order, the one its command
//!   answers (the machine-mode ones with their own sequence number and a
//!   valid checksum); no `err`;
//! - on UART0, no byte found the receive FIFO full;
//! - every frame's pulses are the host's duties, on time: the stream never
//!   delays a frame;
//! - the port tasks' longest wait for the CPU, as the image measured it.
//!
//! And DMX512 at the full universe rate (512 slots, about 44 frames a
//! second) for a minute, across two loop generations, with a change in
//! every tenth frame (of a slot past the head's ten): the head's decoder
//! counts every frame good, none short, long, of another start code or
//! garbled (its `dmx` counters, asked over UART0 at the end), and no frame
//! of the head's was late (none logged as skipped).

use std::{fmt::Write as _, path::Path, time::Duration};

use anyhow::Result;
use idle_head_core::console::checksum;

use super::{
    dmx,
    node::{LineStream, StreamLine, UartScript},
    run::{self, Boot, Report},
    stages::{conclude, shipped_image},
};
use crate::project::Metadata;

/// Stage names.
pub const UART_STREAM_STAGE: &str = "Pico image in the RP2040 emulator: a line every 2 ms on \
     UART0 for 10 minutes: every line answered once, in order, none lost, no frame late";
/// See [`UART_STREAM_STAGE`].
pub const USB_STREAM_STAGE: &str = "Pico image in the RP2040 emulator: a line every 2 ms on \
     USB for 10 minutes: every line answered once, in order, none lost, no frame late";

/// Stage name.
pub const DMX_STREAM_STAGE: &str = "Pico image in the RP2040 emulator: DMX512 at the full \
     universe rate for a minute across two loop generations: every frame decoded, none lost";

/// When the stream starts (the fade-in is over), the time between lines,
/// how long it lasts.
const START: Duration = Duration::from_secs(3);
const EVERY: Duration = Duration::from_millis(2);
pub const LENGTH: Duration = Duration::from_secs(600);

/// The cycle of lines, 20 ms of them.
const CYCLE: [StreamLine; 10] = [
    StreamLine::Plain("center"),
    StreamLine::Machine("watch off"),
    StreamLine::Plain("watch off"),
    StreamLine::Machine("watch off"),
    StreamLine::Plain("watch off"),
    StreamLine::Plain("idle on"),
    StreamLine::Machine("watch off"),
    StreamLine::Plain("watch off"),
    StreamLine::Machine("watch off"),
    StreamLine::Plain("watch off"),
];

/// The stream on `port` (`"uart"` or `"usb"`) for `length`, checked (see
/// the module docs).
pub fn test_stream(
    root: &Path,
    metadata: &Metadata,
    port: &'static str,
    length: Duration,
) -> Result<()> {
    let elf = shipped_image(root, metadata)?;
    let count = usize::try_from(length.as_micros() / EVERY.as_micros()).unwrap_or(usize::MAX);
    let time = START + length + Duration::from_secs(1);
    let mut report = run::run_with(root, &elf, time, wall(length), |config| {
        config.stream = Some(LineStream {
            port,
            start: START,
            every: EVERY,
            count,
            lines: CYCLE.to_vec(),
        });
    })?;
    run::check(&mut report)?;
    print!("{}", report.table());
    conclude(&report, check(&report, port, count))
}

/// What line `k` of the stream is answered.
fn expected(k: usize) -> Expected {
    match CYCLE[k % CYCLE.len()] {
        StreamLine::Machine(_) => Expected::Machine(k % 100_000),
        StreamLine::Plain("center") => Expected::Starts("ok center ms="),
        StreamLine::Plain("idle on") => Expected::Starts("ok idle=100"),
        StreamLine::Plain(_) => Expected::Exactly("ok watch=off"),
    }
}

/// A reply as the stream's check wants it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Expected {
    Exactly(&'static str),
    Starts(&'static str),
    /// `#<n> ok watch=off *<crc>`.
    Machine(usize),
}

impl Expected {
    fn fits(self, reply: &str) -> bool {
        match self {
            Self::Exactly(text) => reply == text,
            Self::Starts(text) => reply.starts_with(text),
            Self::Machine(n) => machine_ok(reply) == Some(n),
        }
    }
}

/// The sequence number of a machine-mode `ok watch=off` reply with a valid
/// checksum.
fn machine_ok(reply: &str) -> Option<usize> {
    let (body, crc) = reply.rsplit_once(" *")?;
    let rest = body.strip_prefix('#')?;
    let (seq, verdict) = rest.split_once(' ')?;
    let crc_ok = u8::from_str_radix(crc, 16).ok()? == checksum(body.as_bytes());
    (crc_ok && verdict == "ok watch=off").then(|| seq.parse().ok())?
}

/// The replies `port` sent in `boot`, without their line ends.
fn replies(boot: &Boot, port: &str) -> Vec<String> {
    let bytes = if port == "usb" { &boot.usb } else { &boot.uart };
    String::from_utf8_lossy(bytes)
        .split_terminator("\r\n")
        .map(str::to_owned)
        .collect()
}

/// The checks of the module docs: a summary and the problems found.
fn check(report: &Report, port: &str, count: usize) -> (String, Vec<String>) {
    let Some(boot) = report.boots.first() else {
        return (String::new(), vec!["no boot".to_owned()]);
    };
    let replies = replies(boot, port);
    let mut problems = Vec::new();
    for (k, reply) in replies.iter().enumerate().take(count) {
        let want = expected(k);
        if !want.fits(reply) && problems.len() < 5 {
            problems.push(format!("line {k}: `{reply}`, not {want:?}"));
        }
    }
    if replies.len() != count {
        problems.push(format!("{} replies to {count} lines", replies.len()));
    }
    if boot.uart_overruns > 0 {
        problems.push(format!(
            "{} bytes found UART0's receive FIFO full",
            boot.uart_overruns
        ));
    }
    let sets = boot
        .log
        .iter()
        .filter(|(_, line)| line.message.starts_with("loop set "))
        .count();
    let summary = format!(
        "{port} stream: {count} lines, one every {} ms; {} replies; {} bytes lost at UART0's \
         receive FIFO; {sets} loop sets generated meanwhile\n",
        EVERY.as_millis(),
        replies.len(),
        boot.uart_overruns,
    );
    (summary, problems)
}

/// How long DMX streams.
const DMX_LENGTH: Duration = Duration::from_secs(60);

/// DMX at the full universe rate for a minute (see the module docs).
pub fn test_dmx(root: &Path, metadata: &Metadata) -> Result<()> {
    let elf = shipped_image(root, metadata)?;
    // A change every 0.23 s (about every tenth frame): the frames that
    // carry one are counted by the harness; the last one at the end.
    let end = START + DMX_LENGTH;
    let mut text = String::new();
    let mut at = START;
    let mut k = 0_u32;
    while at < end {
        let _ = writeln!(text, "{:.3} 11={}", at.as_secs_f64(), k % 2 * 100);
        at += Duration::from_millis(230);
        k += 1;
    }
    let changes = dmx::parse(&text)?;
    let query = end + Duration::from_millis(50);
    let mut report = run::run_with(
        root,
        &elf,
        query + Duration::from_secs(1),
        wall(DMX_LENGTH),
        |config| {
            dmx::configure(config, &changes);
            config.uart = vec![UartScript::new(0, b"dmx\n".to_vec(), query)];
        },
    )?;
    run::check(&mut report)?;
    print!("{}", report.table());
    // (The pulses are not held to the idle's own: a console on the line
    // engages the show layer, mix 0 or not. What is checked is that no
    // frame was late.)
    let (text, problems) = report.boots.first().map_or_else(
        || (String::new(), vec!["no boot".to_owned()]),
        |boot| {
            let reply = boot.uart_replies().into_iter().next().unwrap_or_default();
            check_dmx(boot, &reply, changes.len())
        },
    );
    print!("{text}");
    if problems.is_empty() {
        Ok(())
    } else {
        anyhow::bail!("{}", problems.join("; "))
    }
}

/// The wall time a run of `length` may take.
fn wall(length: Duration) -> Duration {
    (START + length) * 3 + Duration::from_secs(120)
}

/// The `dmx` counters of its `reply` against the frames sent in `boot`:
/// every one good.
pub(super) fn check_dmx(boot: &Boot, reply: &str, changes: usize) -> (String, Vec<String>) {
    let mut problems = Vec::new();
    let counter = |name: &str| -> Option<u64> {
        reply
            .split(' ')
            .find_map(|field| field.strip_prefix(name)?.strip_prefix('=')?.parse().ok())
    };
    let good = counter("good").unwrap_or(0);
    for name in ["short", "long", "start_code", "garbled"] {
        if counter(name) != Some(0) {
            problems.push(format!("`{name}` is not 0 in `{reply}`"));
        }
    }
    // The harness numbers the frames from 0: the last change's frame, and
    // the few sent between it and the query, were all counted.
    let sent = boot.dmx_frames.last().map_or(0, |&frame| frame + 1);
    if boot.dmx_changes.len() != changes || good < sent {
        problems.push(format!(
            "{good} good frames, {sent} sent by the last change ({} of {changes} changes seen)",
            boot.dmx_changes.len()
        ));
    }
    let late: Vec<&str> = boot
        .log
        .iter()
        .map(|(_, line)| line.message.as_str())
        .filter(|message| message.contains("skipped"))
        .collect();
    if let Some(first) = late.first() {
        problems.push(format!("{} frames late: `{first}`", late.len()));
    }
    let sets = boot
        .log
        .iter()
        .filter(|(_, line)| line.message.starts_with("loop set "))
        .count();
    let summary = format!(
        "DMX: {sent} frames of 512 slots sent by the last change, {good} counted good; \
         {sets} loop sets generated meanwhile; `{reply}`\n"
    );
    (summary, problems)
}
