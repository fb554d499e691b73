//! A scripted console exchange over the Pico's UART0 and its USB serial
//! port in the emulator.
//!
//! The harness puts [`SCRIPT`] on the RX line (GP1) at 115200 baud, one
//! byte every 86.8 µs, from [`START`] on: after the fade-in, while the
//! idle motion plays; at [`USB_START`] the emulator's CDC-ACM host (which
//! has enumerated and configured the device at boot) sends it again over
//! USB. Every byte sent back is recorded. The check, for each port:
//! exactly one reply line per script line, each the reply the host
//! computes with the same core `Session` and the firmware's own handler
//! (`src/bin/pico/handler.rs`, compiled here too), in order. The frames
//! are checked as always, so the exchange must not change a pulse: the
//! script's one motion command, `center`, asks for the pose the head
//! already holds.

use std::fmt::Write as _;
use std::time::Duration;

use idle_head::console::checksum;

use super::pico_handler::{PicoSession, Queue, QueueHandler};

/// When the first byte goes out: 3 s, after the 2 s fade-in.
pub const START: Duration = Duration::from_secs(3);
/// When the same script goes to the USB serial port: 4 s.
pub const USB_START: Duration = Duration::from_secs(4);
/// One byte at 115200 baud, 8N1: 10 bits.
pub const BYTE_TIME: Duration = Duration::from_nanos(1_000_000_000 * 10 / 115_200);

/// The lines sent, each with its line end: good and bad commands, every
/// line end, an overlong line, a control byte and a machine-mode line
/// (its checksum is computed in [`script`]).
const SCRIPT: &[&[u8]] = &[
    b"help\r\n",
    b"status\n",
    b"nodd\r\n",
    b"servo yaw neutral 1500\r",
    b"center\r\n",
    b"look 10 up\n",
    b"save\r\n",
    b"nod\x07\r\n",
    b"seed 4294967296\n",
];

/// The bytes of the whole script.
pub fn script() -> Vec<u8> {
    let mut bytes: Vec<u8> = SCRIPT.concat();
    // An overlong line: one byte past the protocol's 96.
    bytes.extend(std::iter::repeat_n(b'a', 97));
    bytes.extend(b"\r\n");
    // Machine mode: `#<seq> <command> *<crc>`.
    let body = "#7 help";
    let crc = checksum(body.as_bytes());
    bytes.extend(format!("{body} *{crc:02x}\r\n").into_bytes());
    bytes
}

/// The replies the firmware must send for `script`, one per line.
pub fn expected(script: &[u8]) -> Vec<Vec<u8>> {
    // The firmware's frame task drains its queue; the script holds fewer
    // actions than the queue holds, so here it never needs draining.
    static QUEUE: Queue = Queue::new();
    let mut session = PicoSession::new();
    let mut handler = QueueHandler::new(&QUEUE);
    let mut replies = Vec::new();
    session.feed(script, &mut handler, |reply| replies.push(reply.to_vec()));
    replies
}

/// What UART0 sent against what it should have; the transcript and the
/// problems found.
pub fn check(script: &[u8], sent: &[u8]) -> (String, Vec<String>) {
    let want = expected(script);
    let got: Vec<&[u8]> = sent
        .split_inclusive(|&b| b == b'\n')
        .filter(|line| !line.is_empty())
        .collect();
    let mut transcript = String::new();
    let mut problems = Vec::new();
    let lines: Vec<&[u8]> = script
        .split_inclusive(|&b| b == b'\n' || b == b'\r')
        .filter(|line| !matches!(line, [b'\n' | b'\r']))
        .collect();
    for (i, want) in want.iter().enumerate() {
        let line = lines.get(i).map_or_else(String::new, |l| printable(l));
        let _ = writeln!(transcript, "  > {line}");
        match got.get(i) {
            Some(reply) => {
                let _ = writeln!(transcript, "  < {}", printable(reply));
                if reply != want {
                    problems.push(format!(
                        "UART reply {} is `{}`, not `{}`",
                        i + 1,
                        printable(reply),
                        printable(want)
                    ));
                }
            }
            None => {
                let _ = writeln!(transcript, "  < (nothing)");
            }
        }
    }
    if got.len() != want.len() {
        problems.push(format!(
            "{} reply lines over the UART for {} lines sent",
            got.len(),
            want.len()
        ));
    }
    if got.last().is_some_and(|l| !l.ends_with(b"\r\n")) {
        problems.push("the last UART reply does not end in CR LF".to_owned());
    }
    (transcript, problems)
}

/// `bytes` with its line end dropped and other control bytes escaped.
fn printable(bytes: &[u8]) -> String {
    let text = bytes
        .strip_suffix(b"\r\n")
        .or_else(|| bytes.strip_suffix(b"\n"))
        .or_else(|| bytes.strip_suffix(b"\r"))
        .unwrap_or(bytes);
    text.utf8_chunks()
        .flat_map(|chunk| {
            let valid = chunk.valid().chars().map(|c| {
                if c.is_control() {
                    format!("\\x{:02x}", u32::from(c))
                } else {
                    c.to_string()
                }
            });
            let invalid = chunk.invalid().iter().map(|b| format!("\\x{b:02x}"));
            valid.chain(invalid).collect::<Vec<_>>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_expected_reply_per_script_line() {
        let script = script();
        let want = expected(&script);
        assert_eq!(want.len(), SCRIPT.len() + 2);
        assert!(want[0].starts_with(b"ok commands: help"));
        assert_eq!(want[1], b"err state not available yet\r\n");
        assert!(want.iter().all(|r| r.ends_with(b"\r\n")));
    }

    #[test]
    fn a_missing_or_wrong_reply_is_a_problem() {
        let script = script();
        let all: Vec<u8> = expected(&script).concat();
        assert!(check(&script, &all).1.is_empty());
        let short = &all[..all.len() - 3];
        assert!(!check(&script, short).1.is_empty());
        let mut wrong = all.clone();
        wrong[0] = b'x';
        assert!(!check(&script, &wrong).1.is_empty());
        assert!(!check(&script, &[]).1.is_empty());
    }
}
