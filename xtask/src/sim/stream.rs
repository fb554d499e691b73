//! Streams into the shipped image, each line answered once, in order, no
//! frame late: a line every 2 ms on UART0 or USB, a UART flood, a framing
//! error, DMX512 for a minute (docs/dev/emulators.md, "Streams").

use std::{path::Path, time::Duration};

use anyhow::Result;
use idle_head_core::console::checksum;

use super::Boot;
use super::{
    dmx,
    exchange::machine,
    node::{LineStream, StreamLine, UartScript},
    run::Report,
    stages::{WALL, checked_run},
};
use crate::{log::number, project::Metadata};

pub const UART_STREAM_STAGE: &str = "Pico image in the RP2040 emulator: a line every 2 ms on \
     UART0 for a minute, across loop generations: every line answered once, in order, none \
     lost, no frame late";
pub const USB_STREAM_STAGE: &str = "Pico image in the RP2040 emulator: a line every 2 ms on \
     USB for a minute, across loop generations: every line answered once, in order, none \
     lost, no frame late";
pub const DMX_STREAM_STAGE: &str = "Pico image in the RP2040 emulator: DMX512 at the full \
     universe rate for a minute across two loop generations: every frame decoded, none lost";
pub const FLOOD_STAGE: &str = "Pico image in the RP2040 emulator: a UART flood with no \
     flow control: every line answered once, in order, no byte lost, no frame late, the \
     console asleep while its replies wait";
pub const NOISE_STAGE: &str = "Pico image in the RP2040 emulator: a byte with a framing \
     error on UART0: its line answered `err line bytes lost`, the next one `ok`";

/// The stream's start (after the fade-in), line spacing, and length: a
/// minute in `cargo xtask test`, 10 minutes in the soak (`cargo xtask sim
/// --stream`, which CI runs).
const START: Duration = Duration::from_secs(3);
const EVERY: Duration = Duration::from_millis(2);
pub const TEST_LENGTH: Duration = Duration::from_secs(60);
pub const LENGTH: Duration = Duration::from_secs(600);
/// A stream must see a loop set generated every this long, at least, so
/// that its lines meet the generator's work (one is ready about every 20 s).
const GENERATION: Duration = Duration::from_secs(30);

/// The stream's cycle, 20 ms: two actions a frame (answered once a frame
/// takes them), settings, and machine-mode lines.
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

/// A reply as a check wants it: exactly a text, starting with one, or in
/// machine mode (`#<n> <text>… *<crc>` with a valid checksum).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Want {
    Exactly(&'static str),
    Starts(&'static str),
    Machine(usize, &'static str),
}

impl Want {
    fn fits(self, reply: &str) -> bool {
        let crc_ok = |(body, crc): (&str, &str)| {
            u8::from_str_radix(crc, 16) == Ok(checksum(body.as_bytes()))
        };
        match self {
            Self::Exactly(text) => reply == text,
            Self::Starts(text) => reply.starts_with(text),
            Self::Machine(n, text) => {
                reply.starts_with(&format!("#{n} {text}"))
                    && reply.rsplit_once(" *").is_some_and(crc_ok)
            }
        }
    }
}

/// Boot 0's replies on UART0 (or `usb`) against `want` for `count` lines:
/// them, and the problems (the first five misfits, a count off, overruns).
fn replies(
    report: &Report,
    usb: bool,
    count: usize,
    want: impl Fn(usize) -> Want,
) -> Result<(Vec<String>, Vec<String>)> {
    let boot = report.first()?;
    let replies = boot.replies(usb);
    let mut problems: Vec<String> = (replies.iter().enumerate())
        .filter(|(k, reply)| !want(*k).fits(reply))
        .take(5)
        .map(|(k, reply)| format!("reply {k} is `{reply}`, not {:?}", want(k)))
        .collect();
    if replies.len() != count {
        problems.push(format!("{} replies to {count} lines", replies.len()));
    }
    let overruns = boot.uart_overruns;
    if overruns > 0 {
        problems.push(format!("{overruns} bytes found UART0's receive FIFO full"));
    }
    Ok((replies, problems))
}

/// Loop sets generated in `boot` from `from` on.
fn sets(boot: &Boot, from: Duration) -> usize {
    let from = from.as_secs_f64() * 1e9;
    let log = boot.log.iter().filter(|(at, _)| *at >= from);
    log.filter(|(_, line)| line.message.starts_with("loop set "))
        .count()
}

fn wall(length: Duration) -> Duration {
    (START + length) * 3 + Duration::from_secs(120)
}

/// A line every 2 ms on `port` (`"uart"` or `"usb"`) for `length`.
pub fn test_stream(
    root: &Path,
    metadata: &Metadata,
    port: &'static str,
    length: Duration,
) -> Result<()> {
    let count = usize::try_from(length.as_micros() / EVERY.as_micros()).unwrap_or(usize::MAX);
    let time = START + length + Duration::from_secs(1);
    let report = checked_run(root, metadata, time, wall(length), |config| {
        config.stream = Some(LineStream {
            port,
            start: START,
            every: EVERY,
            count,
            lines: CYCLE.to_vec(),
        });
    })?;
    print!("{}", report.table());
    let (replies, mut problems) = replies(&report, port == "usb", count, |k| {
        match CYCLE[k % CYCLE.len()] {
            StreamLine::Machine(_) => Want::Machine(k % 100_000, "ok watch=off"),
            StreamLine::Plain("center") => Want::Starts("ok center ms="),
            StreamLine::Plain("idle on") => Want::Starts("ok idle=100"),
            StreamLine::Plain(_) => Want::Exactly("ok watch=off"),
        }
    })?;
    let sets = sets(report.first()?, START);
    println!(
        "{port} stream: {count} lines, one every {} ms; {} replies; {sets} loop sets generated \
         meanwhile; {} instructions a line, the run's all",
        EVERY.as_millis(),
        replies.len(),
        report.end.instructions / count.max(1) as u64
    );
    let least = usize::try_from(length.as_secs() / GENERATION.as_secs()).unwrap_or(usize::MAX);
    if sets < least {
        let problem = format!("{sets} loop sets generated while the lines came, not {least}");
        problems.push(problem);
    }
    report.conclude(problems)
}

const FLOOD_LINES: usize = 100;

/// 100 `status` lines back to back at 3 s (0.7 ms a line, 9.5 a reply),
/// as many in machine mode at 5 s, one more at 7 s.
pub fn test_flood(root: &Path, metadata: &Metadata) -> Result<()> {
    let time = Duration::from_millis(7_500);
    let numbered = (1..=FLOOD_LINES).flat_map(|n| machine(&format!("#{n} status")));
    let report = checked_run(root, metadata, time, WALL, |config| {
        config.uart = vec![
            UartScript::new(0, b"status\r\n".repeat(FLOOD_LINES), Duration::from_secs(3)),
            UartScript::new(0, numbered.collect::<Vec<u8>>(), Duration::from_secs(5)),
            UartScript::new(0, b"status\r\n", Duration::from_secs(7)),
        ];
    })?;
    print!("{}", report.table());
    let lines = 2 * FLOOD_LINES + 1;
    let (replies, mut problems) = replies(&report, false, lines, |k| match k {
        k if (FLOOD_LINES..2 * FLOOD_LINES).contains(&k) => {
            Want::Machine(k + 1 - FLOOD_LINES, "ok mode=")
        }
        _ => Want::Starts("ok mode="),
    })?;
    println!("UART flood: {} replies for {lines} lines", replies.len());
    // While replies wait for the UART, the console sleeps: the whole run,
    // boot and idle included, costs under 100k instructions a line (a
    // writer that spun until the line drained cost 1M).
    let per_line = report.end.instructions / lines as u64;
    println!("UART flood: {per_line} instructions a line, the run's all");
    if per_line > 100_000 {
        problems.push(format!(
            "{per_line} instructions a line: the console spins while its replies wait"
        ));
    }
    report.conclude(problems)
}

/// `sta`, a byte with a framing error, `tus`, then `status`.
pub fn test_noise(root: &Path, metadata: &Metadata) -> Result<()> {
    let time = Duration::from_millis(3_500);
    let report = checked_run(root, metadata, time, WALL, |config| {
        let noisy = UartScript::new(0, b"staXtus\r\nstatus\r\n", Duration::from_secs(3));
        config.uart = vec![UartScript {
            errors: vec![3],
            ..noisy
        }];
    })?;
    let (replies, problems) = replies(&report, false, 2, |k| match k {
        0 => Want::Starts("err line bytes lost"),
        1 => Want::Starts("ok mode="),
        _ => Want::Exactly(""),
    })?;
    println!("UART0, `sta` + a byte with a framing error + `tus`, then `status`:");
    for reply in replies {
        println!("  < {reply}");
    }
    report.conclude(problems)
}

const DMX_LENGTH: Duration = Duration::from_secs(60);

/// DMX at the full universe rate for a minute; `dmx` asked at the end.
pub fn test_dmx(root: &Path, metadata: &Metadata) -> Result<()> {
    // The harness counts the frames that carry a change; the last one at the end.
    let end = START + DMX_LENGTH;
    let changes = dmx::alternating(START, end)?;
    let query = end + Duration::from_millis(50);
    let time = query + Duration::from_secs(1);
    let report = checked_run(root, metadata, time, wall(DMX_LENGTH), |config| {
        config.dmx = Some(dmx::line(&changes));
        config.uart = vec![UartScript::new(0, b"dmx\n", query)];
    })?;
    print!("{}", report.table());
    // (The pulses are not held to the idle's own: a console on the line
    // engages the show layer, mix 0 or not. No frame may be late.)
    crate::project::verdict(&check_dmx(report.first()?, changes.len()))
}

/// The counters of `boot`'s `ok dmx=` reply against the frames it sent
/// (`changes` of them changes): every one good, no frame late. Prints a
/// summary; the problems.
pub(super) fn check_dmx(boot: &Boot, changes: usize) -> Vec<String> {
    let reply = boot.reply("ok dmx=");
    let counter = |name| number(&reply, name).ok();
    let mut problems: Vec<String> = ["short", "long", "start_code", "garbled"]
        .into_iter()
        .filter(|name| counter(name) != Some(0))
        .map(|name| format!("`{name}` is not 0 in `{reply}`"))
        .collect();
    // The harness numbers the frames from 0: the last change's frame, and
    // the few sent between it and the query, were all counted.
    let good = counter("good").unwrap_or(0);
    let sent = boot.dmx_frames.last().map_or(0, |&frame| frame + 1);
    let seen = boot.dmx_changes.len();
    if seen != changes || good < sent {
        problems.push(format!(
            "{good} good frames, {sent} sent by the last change ({seen} of {changes} changes seen)"
        ));
    }
    let late: Vec<&str> = (boot.log.iter().map(|(_, line)| line.message.as_str()))
        .filter(|message| message.contains("skipped"))
        .collect();
    if let Some(first) = late.first() {
        problems.push(format!("{} frames late: `{first}`", late.len()));
    }
    let sets = sets(boot, Duration::ZERO);
    println!(
        "DMX: {sent} frames of 512 slots sent by the last change, {good} counted good; {sets} loop \
         sets generated meanwhile; `{reply}`"
    );
    problems
}
