//! A flood on the Pico image's UART in the emulator: more lines than
//! the head can answer at 115200 baud, with no flow control.
//!
//! At 3 s the harness sends [`FLOOD_LINES`] `status` lines back to back at
//! the line rate (8 bytes each, 0.7 ms a line); at 5 s as many in machine
//! mode (`#<n> status *<crc>`, n from 1). Each reply is about 110 bytes
//! (9.5 ms at the line rate, which the harness's UART keeps), so the
//! receive side (the UART's 32-byte FIFO and the console's 64-byte buffer)
//! fills, and the bytes that find the FIFO full are lost, as on the chip;
//! the harness sets the PL011's overrun bit. At 7 s, when every reply has
//! gone out, a line end alone (it ends what is left of the flood's last
//! line, as docs/user/protocol.md advises after a loss) and one more `status`.
//!
//! The UART driver reports an overrun once the bytes received before it
//! have been read, and by then some received after it may have been read
//! too: the line said to have lost bytes can be a line late, and the lines
//! that ran together before it get whatever reply they make. The check:
//! - every reply is a `status` reply, plain or in machine mode, or an
//!   `err` (lines lost whole get none: docs/user/protocol.md tells programs to
//!   wait for each reply, or to use machine mode);
//! - every machine-mode `ok` carries a sequence number that was sent, in
//!   increasing order, and a valid checksum: a program sees exactly which
//!   of its lines were carried out;
//! - bytes were lost, and at least one reply says so;
//! - the line after the flood gets its `ok`: the console works on;
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
     flow control: lines that lost bytes say so, the console works on, no frame late";

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
/// What a line that lost bytes is answered.
const LOST: &str = "err line bytes lost";
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
            ([b"\r\n", LINE].concat(), AT[2]),
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
    let is_err = |r: &str| {
        r.starts_with("err ")
            || r.split_once(' ')
                .is_some_and(|(seq, rest)| seq.starts_with('#') && rest.starts_with("err "))
    };
    let mut problems: Vec<String> = replies
        .iter()
        .filter(|r| !r.starts_with(STATUS) && machine_ok(r).is_none() && !is_err(r))
        .map(|r| format!("an unexpected reply `{r}`"))
        .collect();
    let plain = replies.iter().filter(|r| r.starts_with(STATUS)).count();
    let seqs: Vec<usize> = replies.iter().filter_map(|r| machine_ok(r)).collect();
    let errors = replies.iter().filter(|r| is_err(r)).count();
    let lost = replies
        .iter()
        .filter(|r| r.contains(LOST.trim_start_matches("err ")))
        .count();
    if !seqs.windows(2).all(|w| w[0] < w[1]) || seqs.iter().any(|&n| n == 0 || n > FLOOD_LINES) {
        problems.push(format!(
            "machine-mode replies out of order or never sent: {seqs:?}"
        ));
    }
    if boot.uart_overruns == 0 || lost == 0 {
        problems.push(format!(
            "the flood lost {} bytes and {lost} replies said so: both must be more than 0",
            boot.uart_overruns
        ));
    }
    if replies.len() > 2 * FLOOD_LINES + 1 {
        problems.push(format!(
            "{} replies to {} lines",
            replies.len(),
            2 * FLOOD_LINES + 1
        ));
    }
    let last_ok = replies.last().is_some_and(|r| r.starts_with(STATUS));
    if !last_ok {
        problems.push("the line after the flood got no `ok` reply".to_owned());
    }
    let summary = format!(
        "UART flood: {FLOOD_LINES} plain and {FLOOD_LINES} machine-mode lines, then a line end \
         and 1 more line; {} \
         bytes lost at the full receive FIFO; {} replies: {plain} plain `{STATUS}…`, {} machine \
         `#<n> ok` (n = {:?}…), {errors} `err` ({lost} of them `{LOST} …`); the last line \
         answered `{STATUS}…`: {last_ok} (`{}`)\n",
        boot.uart_overruns,
        replies.len(),
        seqs.len(),
        &seqs[..seqs.len().min(8)],
        replies.last().map_or("", String::as_str),
    );
    (summary, problems)
}
