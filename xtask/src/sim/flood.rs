//! A flood on the Pico image's UART in the emulator: more lines than the
//! replies keep up with at 115200 baud, with no flow control, and none lost.
//!
//! At 3 s the harness sends [`FLOOD_LINES`] `status` lines back to back at
//! the line rate (8 bytes each, 0.7 ms a line); at 5 s as many in machine
//! mode (`#<n> status *<crc>`, n from 1). Each reply is about 110 bytes (9.5
//! ms at the line rate, which the harness's UART keeps), so the lines arrive
//! more than ten times faster than their replies leave: on a PL011 read by
//! its interrupt the 32-byte FIFO overflows (the harness models the overrun
//! as the chip does). The board receives by DMA into a ring in RAM
//! (`crates/rp/src/uart.rs`), which holds them all. At 7 s, when every reply
//! has gone out, one more `status`.
//!
//! The check:
//! - no byte found the receive FIFO full;
//! - every line got exactly one reply, in order: the plain ones `ok mode=…`,
//!   the machine-mode ones `#<n> ok mode=… *<crc>` with n = 1, 2, … and a
//!   valid checksum, then the last line's `ok`; no `err`;
//! - every frame's pulses are the host's, on time: the flood never delays
//!   a frame.

use std::{path::Path, time::Duration};

use anyhow::Result;

use super::{
    node::UartScript,
    run::{self, Report},
    stages::{WALL, conclude, shipped_image},
};
use crate::project::Metadata;
use idle_head_core::console::checksum;

/// Stage name.
pub const FLOOD_STAGE: &str = "Pico image in the RP2040 emulator: a UART flood with no \
     flow control: every line answered once, in order, no byte lost, no frame late";

/// Lines in each flood.
pub const FLOOD_LINES: usize = 100;
/// When the plain flood starts, the machine-mode one, and the last line.
const AT: [Duration; 3] = [
    Duration::from_secs(3),
    Duration::from_secs(5),
    Duration::from_secs(7),
];
/// The whole run.
const TIME: Duration = Duration::from_millis(7_500);
/// The line flooded, and the last one.
const LINE: &[u8] = b"status\r\n";
/// What a `status` line is answered.
const STATUS: &str = "ok mode=";

/// Runs the flood and checks it (see the module docs).
pub fn test_flood(root: &Path, metadata: &Metadata) -> Result<()> {
    let elf = shipped_image(root, metadata)?;
    let mut report = run::run_with(root, &elf, TIME, WALL, |config| {
        let machine: Vec<u8> = (1..=FLOOD_LINES).flat_map(machine_line).collect();
        config.uart = [
            (LINE.repeat(FLOOD_LINES), AT[0]),
            (machine, AT[1]),
            (LINE.to_vec(), AT[2]),
        ]
        .into_iter()
        .map(|(bytes, start)| UartScript::new(0, bytes, start))
        .collect();
    })?;
    run::check(&mut report)?;
    print!("{}", report.table());
    conclude(&report, check(&report))
}

/// Machine-mode `status` with sequence number `n`, and its line end.
fn machine_line(n: usize) -> Vec<u8> {
    let body = format!("#{n} status");
    format!("{body} *{:02x}\r\n", checksum(body.as_bytes())).into_bytes()
}

/// The sequence number of a machine-mode `status` reply with a valid
/// checksum (`#<n> ok mode=… *<crc>`).
fn machine_ok(reply: &str) -> Option<usize> {
    let (body, crc) = reply.rsplit_once(" *")?;
    let (seq, rest) = body.strip_prefix('#')?.split_once(' ')?;
    let crc_ok = u8::from_str_radix(crc, 16).ok()? == checksum(body.as_bytes());
    (crc_ok && rest.starts_with(STATUS)).then(|| seq.parse().ok())?
}

/// The checks of the module docs on the UART's replies: a summary and the
/// problems found.
fn check(report: &Report) -> (String, Vec<String>) {
    let Some(boot) = report.boots.first() else {
        return (String::new(), vec!["no boot".to_owned()]);
    };
    let replies = boot.uart_replies();
    let expected = (0..FLOOD_LINES)
        .map(|_| None)
        .chain((1..=FLOOD_LINES).map(Some))
        .chain([None]);
    let mut problems = Vec::new();
    for (i, (reply, seq)) in replies.iter().zip(expected).enumerate() {
        let right = match seq {
            None => reply.starts_with(STATUS),
            Some(n) => machine_ok(reply) == Some(n),
        };
        if !right && problems.len() < 5 {
            let want = seq.map_or_else(
                || format!("`{STATUS}…`"),
                |n| format!("`#{n} {STATUS}… *<crc>`"),
            );
            problems.push(format!("reply {} is `{reply}`, not {want}", i + 1));
        }
    }
    let lines = 2 * FLOOD_LINES + 1;
    if replies.len() != lines {
        problems.push(format!("{} replies to {lines} lines", replies.len()));
    }
    if boot.uart_overruns > 0 {
        problems.push(format!(
            "{} bytes found the receive FIFO full",
            boot.uart_overruns
        ));
    }
    let summary = format!(
        "UART flood: {FLOOD_LINES} plain and {FLOOD_LINES} machine-mode `status` lines, then 1 \
         more; {} replies for {lines} lines, {} bytes lost at the receive FIFO\n",
        replies.len(),
        boot.uart_overruns,
    );
    (summary, problems)
}
