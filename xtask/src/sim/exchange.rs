//! A scripted console exchange over the Pico's UART0, then USB, in the
//! emulator: each reply the one the host's core `ConsoleService` gives
//! (frame-dependent fields masked as `*`). The script moves nothing, so the
//! pulses are checked against the idle as always.

use std::{cell::RefCell, fmt::Write as _, time::Duration};

use embassy_sync::blocking_mutex::Mutex;
use idle_head_core::behaviour::{CommandQueue, ShowLink};
use idle_head_core::console::{
    ConsoleLink, ConsoleService, HeadMode, HeadStatus, PortSession, Shared, SharedService,
    checksum, outcome_reply,
};
use idle_head_core::settings::{RamStorage, Validated};

use super::node::{Chunk, Config, UartScript};
use super::run::Report;

/// When the first byte goes out: 3 s, after the 2 s fade-in.
pub const START: Duration = Duration::from_secs(3);
/// When the same script goes to the USB serial port: 4 s.
pub const USB_START: Duration = Duration::from_secs(4);
/// Between the starts of two lines on the UART: more than the longest
/// reply (160 bytes, 13.9 ms) takes to go out.
const LINE_GAP: Duration = Duration::from_millis(40);

/// The lines sent: good and bad commands, every line end, a control byte;
/// [`script_lines`] adds an overlong and a machine-mode line.
const SCRIPT: &[&[u8]] = &[
    b"help\r\n",
    b"status\n",
    b"nodd\r\n",
    b"servo yaw\r\n",
    b"servo yaw neutral 1500\r",
    b"center\r\n",
    b"look 10 up\n",
    b"seed 7\n",
    b"load\r\n",
    b"status\r\n",
    b"servo yaw min 400\n",
    b"nod\x07\r\n",
    b"seed 4294967296\n",
];

/// The script on UART0 from [`START`], and over USB at [`USB_START`].
pub fn configure(config: &mut Config) {
    let lines = script_lines();
    config.uart = (0_u32..)
        .zip(&lines)
        .map(|(i, line)| UartScript::new(0, line.clone(), START + LINE_GAP * i))
        .collect();
    config.usb = vec![Chunk::new(lines.concat(), USB_START)];
}

/// Boot 0's exchange against the host's replies: prints the transcript;
/// its problems into `report`.
pub fn check(report: &mut Report) {
    let Some(boot) = report.boots.first() else {
        return;
    };
    let lines = script_lines();
    let script = lines.concat();
    let [uart_want, usb_want] = expected(&script);
    let (transcript, problems) = compare(&lines, &uart_want, &boot.uart);
    let (len, out) = (script.len(), boot.uart.len());
    let start = START.as_secs_f64();
    print!(
        "UART0 exchange ({len} bytes in from {start:.1} s at 115200 baud, {out} bytes out):\n{transcript}"
    );
    let mut found: Vec<String> = problems.into_iter().map(|p| format!("UART: {p}")).collect();
    match boot.uart_lines.last() {
        Some(ns) => println!("  (last byte in at {:.4} s)", ns / 1e9),
        None => found.push("the harness did not send the whole UART script".to_owned()),
    }
    if boot.uart_overruns > 0 {
        let n = boot.uart_overruns;
        found.push(format!(
            "{n} UART bytes found the receive FIFO full (the firmware did not read in time)"
        ));
    }
    let (usb, usb_problems) = compare(&lines, &usb_want, &boot.usb);
    match boot.usb_connected {
        Some(ns) => {
            let (at, start, out) = (ns / 1e9, USB_START.as_secs_f64(), boot.usb.len());
            print!(
                "USB CDC-ACM exchange (enumerated and configured at {at:.4} s; {len} bytes in at {start:.1} s, {out} bytes out):\n{usb}"
            );
            found.extend(usb_problems.into_iter().map(|p| format!("USB: {p}")));
        }
        None => found.push("the emulator's USB host did not configure the device".to_owned()),
    }
    if !boot.says(": center: ok") {
        found.push("the frame task did not log the UART's `center` as applied (`frame <n>: center: ok ...`)".to_owned());
    }
    report.problems.extend(found);
}

/// The script's lines, each with its line end.
fn script_lines() -> Vec<Vec<u8>> {
    let mut lines: Vec<Vec<u8>> = SCRIPT.iter().map(|line| line.to_vec()).collect();
    // An overlong line: one byte past the protocol's 96.
    lines.push(format!("{}\r\n", "a".repeat(97)).into_bytes());
    lines.push(machine("#7 help"));
    lines
}

/// A line in machine mode: `body` (`#<seq> <command>`), then ` *<crc>`.
pub fn machine(body: &str) -> Vec<u8> {
    format!("{body} *{:02x}\r\n", checksum(body.as_bytes())).into_bytes()
}

/// The replies to `script` on the UART, then USB, from one service.
fn expected(script: &[u8]) -> [Vec<Vec<u8>>; 2] {
    let queue: &'static CommandQueue = Box::leak(Box::new(CommandQueue::new()));
    let link: &'static ConsoleLink = Box::leak(Box::new(ConsoleLink::new()));
    // As on the board from its fade-in on; the rest is masked ([`mask`]).
    link.publish(HeadStatus {
        mode: HeadMode::Running,
        ..HeadStatus::default()
    });
    let service = ConsoleService::with_defaults(queue, link, RamStorage::new())
        // As on the board: DMX on, no frames in this run (`dmx=lost`).
        .with_show(Box::leak(Box::new(ShowLink::new())))
        .with_parts(crate::board::pico_parts());
    let service: &'static SharedService<RamStorage> =
        Box::leak(Box::new(Mutex::new(RefCell::new(service))));
    // What the frame task answers a queued action: the mixer's answer on
    // a head whose gaze is at the centre and plays no gesture, as the
    // emulated head's is when the script's one motion (`center`) arrives.
    let behaviour = Validated::DEFAULT.behaviour;
    [0, 1].map(|port| {
        let mut session = PortSession::new();
        let mut handler = Shared::new(service, port);
        let mut replies = Vec::new();
        for &byte in script {
            if let Some(reply) = session.push(byte, &mut handler) {
                replies.push(mask(reply));
            }
            if session.waiting().is_some() {
                let (action, _) = queue.take_asked().expect("the action waits in the queue");
                let outcome = behaviour.check(&action);
                if let Some(reply) = session.finish(|reply| outcome_reply(reply, &outcome)) {
                    replies.push(mask(reply));
                }
            }
        }
        replies
    })
}

/// `reply` with `status`'s frame-dependent values (angles, pulses, uptime;
/// if lists of integers) replaced by `*`.
fn mask(reply: &[u8]) -> Vec<u8> {
    let text = String::from_utf8_lossy(reply);
    if !text.starts_with("ok mode=") {
        return reply.to_vec();
    }
    let integer = |n: &str| n.parse::<i64>().is_ok();
    let mask_word = |word: &str| {
        let numbers = |key: &&str| {
            word.strip_prefix(*key)
                .is_some_and(|v| v.split(',').all(integer))
        };
        match ["mdeg=", "us=", "uptime_ms="].into_iter().find(numbers) {
            Some(key) => format!("{key}*"),
            None => word.to_owned(),
        }
    };
    let words: Vec<String> = text.split(' ').map(mask_word).collect();
    words.join(" ").into_bytes()
}

/// What a port `sent` against `want`, beside the script's `lines`: transcript, problems.
fn compare(lines: &[Vec<u8>], want: &[Vec<u8>], sent: &[u8]) -> (String, Vec<String>) {
    let got: Vec<Vec<u8>> = sent
        .split_inclusive(|&b| b == b'\n')
        .filter(|line| !line.is_empty())
        .map(mask)
        .collect();
    let mut transcript = String::new();
    let mut problems = Vec::new();
    for (i, want) in want.iter().enumerate() {
        let line = lines.get(i).map_or_else(String::new, |l| printable(l));
        let reply = got.get(i);
        let shown = reply.map_or_else(|| "(nothing)".to_owned(), |r| printable(r));
        let _ = writeln!(transcript, "  > {line}\n  < {shown}");
        if reply.is_some_and(|r| r != want) {
            let (n, wanted) = (i + 1, printable(want));
            problems.push(format!("reply {n} is `{shown}`, not `{wanted}`"));
        }
    }
    let (replies, sent) = (got.len(), want.len());
    if replies != sent {
        problems.push(format!("{replies} reply lines for {sent} lines sent"));
    }
    if got.last().is_some_and(|l| !l.ends_with(b"\r\n")) {
        problems.push("the last reply does not end in CR LF".to_owned());
    }
    (transcript, problems)
}

/// `bytes` with its line end dropped, the rest escaped.
fn printable(bytes: &[u8]) -> String {
    let bytes = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    let bytes = bytes.strip_suffix(b"\r").unwrap_or(bytes);
    bytes.escape_ascii().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_expected_reply_per_script_line() {
        let script = script_lines().concat();
        let [uart, usb] = expected(&script);
        for want in [&uart, &usb] {
            assert_eq!(want.len(), SCRIPT.len() + 2);
            assert!(want[0].starts_with(b"ok commands: help"));
            assert!(want.iter().all(|r| r.ends_with(b"\r\n")));
        }
        let text = |r: &Vec<u8>| String::from_utf8_lossy(r).into_owned();
        assert!(
            text(&uart[1])
                .starts_with("ok mode=running mdeg=* us=* faults=0,0,0 off=0 uptime_ms=* fw=")
                && text(&uart[1])
                    .ends_with(" settings=defaults inputs=-,-,-,- seed=board rate=50\r\n"),
            "{}",
            text(&uart[1])
        );
        assert!(
            text(&uart[3]).starts_with("ok yaw neutral=1500 "),
            "{}",
            text(&uart[3])
        );
        assert_eq!(text(&uart[7]), "ok seed=7\r\n");
        assert_eq!(text(&uart[8]), "err storage load: no settings saved\r\n");
        assert!(text(&uart[9]).ends_with(" settings=changed inputs=-,-,-,- seed=7 rate=50\r\n"));
        // The USB run finds the settings the UART run changed.
        assert!(text(&usb[1]).ends_with(" settings=changed inputs=-,-,-,- seed=7 rate=50\r\n"));
    }

    #[test]
    fn status_masks_only_numbers() {
        let masked = mask(b"ok mode=running mdeg=1,-2,3 us=1500,1500,1500 faults=0,0,0 uptime_ms=3020 settings=flash\r\n");
        assert_eq!(
            masked,
            b"ok mode=running mdeg=* us=* faults=0,0,0 uptime_ms=* settings=flash\r\n"
        );
        assert_eq!(
            mask(b"ok mode=running mdeg=x,1"),
            b"ok mode=running mdeg=x,1"
        );
        assert_eq!(mask(b"ok mode=running us="), b"ok mode=running us=");
        assert_eq!(mask(b"ok yaw us=1"), b"ok yaw us=1");
    }

    #[test]
    fn a_missing_or_wrong_reply_is_a_problem() {
        let lines = script_lines();
        let [want, _] = expected(&lines.concat());
        let all: Vec<u8> = want.concat();
        assert!(compare(&lines, &want, &all).1.is_empty());
        let mut wrong = all.clone();
        wrong[0] = b'x';
        for bad in [&all[..all.len() - 3], &wrong, &[]] {
            assert!(!compare(&lines, &want, bad).1.is_empty());
        }
    }
}
