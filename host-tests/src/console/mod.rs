//! The console fuzz harness: random and mutated lines, random byte
//! streams, a reference line discipline, and the checks every reply must
//! pass. A test drives a [`Session`] with any [`Handler`] through
//! [`run_stream`] and checks the replies with [`check_replies`]; a handler
//! that drives a simulated head plugs in the same way.

pub mod head;
mod model;
mod mutate;
pub mod talk;
mod text;

use idle_head_core::command::Command;
use idle_head_core::console::{Handler, InputError, Reply, Session, checksum, parse};
use proptest::prelude::RngExt as _;
use proptest::test_runner::{RngAlgorithm, TestRng};

pub use model::{count_line_ends, reference_lines};
pub use mutate::{mutate, random_bytes, token_line};
pub use text::{
    EDGE_NUMBERS, VOCABULARY, command_text, random_action, random_command, varied_text,
};

/// The line capacity the firmware uses.
pub const LINE: usize = idle_head_core::console::PORT_LINE;
/// The reply buffer the firmware uses.
pub const REPLY: usize = idle_head_core::console::PORT_REPLY;

/// A seeded generator (the same seed, the same cases, on every machine).
///
/// With `FUZZ_SEED=<n>` in the environment every seed is moved by `n`: the
/// fuzz and store tests then run on cases no run has seen, for a soak
/// (`FUZZ_SEED=7 cargo test --release console_fuzz::`). Unset, or 0,
/// the cases are CI's.
#[must_use]
pub fn rng(seed: u64) -> TestRng {
    let moved = crate::env_number::<u64>("FUZZ_SEED").unwrap_or(0);
    let seed = seed ^ moved.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    let mut bytes = [0; 16];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    bytes[8..].copy_from_slice(&(!seed).to_le_bytes());
    TestRng::from_seed(RngAlgorithm::XorShift, &bytes)
}

/// One line for the parser: a valid command (varied spelling), a mutation
/// of one, random vocabulary, or random bytes; with its kind.
pub fn random_line(rng: &mut TestRng) -> (LineKind, Vec<u8>) {
    match rng.random_range(0..20) {
        0..=3 => {
            let command = random_command(rng);
            (LineKind::Valid, varied_text(&command, rng).into_bytes())
        }
        4..=15 => {
            let command = random_command(rng);
            let text = varied_text(&command, rng);
            (LineKind::Mutated, mutate(text.as_bytes(), rng))
        }
        16..=18 => (LineKind::Tokens, token_line(rng)),
        _ => (LineKind::Random, random_bytes(rng, 120)),
    }
}

/// How a test line was made.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LineKind {
    /// A valid command's text.
    Valid,
    /// A valid command's text, mutated.
    Mutated,
    /// Random words of the vocabulary and edge numbers.
    Tokens,
    /// Random bytes.
    Random,
}

/// A random byte stream of about `size` bytes: commands typed with
/// corrections (backspace, DEL), machine-mode lines (good and damaged),
/// mutated lines, NULs and control bytes, invalid UTF-8, overlong lines,
/// line ends of every kind and lines left without one.
pub fn random_stream(rng: &mut TestRng, size: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(size + 1024);
    while out.len() < size {
        match rng.random_range(0..16) {
            0..=3 => out.extend_from_slice(&random_line(rng).1),
            4 | 5 => typed_with_corrections(rng, &mut out),
            6 | 7 => machine_line(rng, &mut out),
            8 => {
                // Overlong: up to several buffers' worth.
                let n = rng.random_range(LINE - 2..LINE * 5);
                out.extend((0..n).map(|_| rng.random_range(b'a'..=b'z')));
            }
            9 => {
                // Invalid UTF-8 in a command.
                const BAD: &[&[u8]] =
                    &[b"\xff", b"\xc3", b"\xc0\x80", b"\xed\xa0\x80", b"\xf4\x90"];
                out.extend_from_slice(b"nod ");
                out.extend_from_slice(BAD[rng.random_range(0..BAD.len())]);
            }
            10 => {
                out.extend_from_slice(b"status");
                out.push(rng.random_range(0..0x20));
            }
            11 => out.extend_from_slice("servo yaw neutral 1500 é€😀".as_bytes()),
            _ => out.extend_from_slice(command_text(&random_command(rng)).as_bytes()),
        }
        if rng.random_bool(0.9) {
            out.extend_from_slice(
                [
                    b"\r\n".as_slice(),
                    b"\n",
                    b"\r",
                    b"\n\r",
                    b"\r\r\n",
                    b"\n\n",
                ][rng.random_range(0..6)],
            );
        }
    }
    out
}

/// A valid command typed with mistakes that backspace (or DEL) corrects,
/// some of them inside multi-byte characters.
fn typed_with_corrections(rng: &mut TestRng, out: &mut Vec<u8>) {
    let text = command_text(&random_command(rng));
    for c in text.chars() {
        if rng.random_bool(0.1) {
            let wrong = ["x", "é", "€", "😀", "\x1b"][rng.random_range(0..5)];
            out.extend_from_slice(wrong.as_bytes());
            out.push(if rng.random_bool(0.5) { 0x08 } else { 0x7f });
        }
        let mut utf8 = [0; 4];
        out.extend_from_slice(c.encode_utf8(&mut utf8).as_bytes());
    }
}

/// `#<seq> <command> *<crc>`, its checksum right or (sometimes) wrong.
fn machine_line(rng: &mut TestRng, out: &mut Vec<u8>) {
    let seq: u32 = rng.random();
    let mut line = format!("#{seq} {}", command_text(&random_command(rng))).into_bytes();
    let mut crc = checksum(&line);
    match rng.random_range(0..10) {
        0 => crc ^= 1 << rng.random_range(0..8),
        1 => line = mutate(&line, rng),
        _ => {}
    }
    out.extend_from_slice(&line);
    if rng.random_bool(0.95) {
        out.extend_from_slice(format!(" *{crc:02x}").as_bytes());
    }
}

/// Feeds `stream` to a fresh session in random chunks (as a transport
/// delivers them) and returns every reply line.
pub fn run_stream<H: Handler>(stream: &[u8], rng: &mut TestRng, handler: &mut H) -> Vec<Vec<u8>> {
    let mut session = Session::<LINE, REPLY>::new();
    let mut replies = Vec::new();
    let mut rest = stream;
    while !rest.is_empty() {
        let n = rng.random_range(1..=rest.len().min(64));
        let (chunk, tail) = rest.split_at(n);
        session.feed(chunk, handler, |reply| replies.push(reply.to_vec()));
        rest = tail;
    }
    replies
}

/// What [`check_replies`] counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReplyCounts {
    /// Line ends in the stream.
    pub lines: usize,
    /// Replies starting `ok` (machine mode included).
    pub ok: usize,
    /// Replies starting `err` (machine mode included).
    pub err: usize,
    /// Replies cut short (ending in `…`).
    pub truncated: usize,
    /// Machine-mode replies.
    pub machine: usize,
}

/// Checks the replies to `stream`: exactly one per line end, each a single
/// well-formed line, and each agreeing with the reference line discipline
/// and the parser about what the line was. Panics with the first problem.
pub fn check_replies(stream: &[u8], replies: &[Vec<u8>]) -> ReplyCounts {
    let ends = count_line_ends(stream);
    let lines = reference_lines(stream, LINE);
    assert_eq!(lines.len(), ends, "reference model and line-end count");
    assert_eq!(replies.len(), ends, "one reply per line end");
    let mut counts = ReplyCounts {
        lines: ends,
        ..ReplyCounts::default()
    };
    for (line, reply) in lines.iter().zip(replies) {
        let text = check_reply_shape(reply);
        let machine = matches!(line, Ok(bytes) if bytes.first() == Some(&b'#'));
        let body = if machine {
            counts.machine += 1;
            check_machine_reply(text)
        } else {
            text
        };
        assert!(
            body.find('…')
                .is_none_or(|i| i + '…'.len_utf8() == body.len()),
            "`…` only at the end: {text:?}"
        );
        if body.ends_with('…') {
            counts.truncated += 1;
        }
        if body.starts_with("ok") {
            counts.ok += 1;
        } else {
            counts.err += 1;
        }
        let context = || format!("line {line:?} → reply {text:?}");
        match line {
            Err(e) => assert!(body.starts_with("err line "), "{e}: {}", context()),
            // Machine mode: a sound envelope's command is judged as any line.
            Ok(bytes) if machine => {
                if let Some(command) = sound_envelope(bytes) {
                    agree(command, body, &context);
                } else {
                    assert!(body.starts_with("err line "), "{}", context());
                }
            }
            Ok(bytes) => agree(bytes, body, &context),
        }
    }
    counts
}

/// The reply's verdict is the parser's.
fn agree(line: &[u8], verdict: &str, context: &dyn Fn() -> String) {
    match parse(line) {
        Ok(_) => assert!(verdict.starts_with("ok"), "{}", context()),
        Err(e) => assert!(
            verdict.starts_with(&format!("err {} ", e.code())),
            "{}",
            context()
        ),
    }
}

/// The command of `#<seq> <command> *<crc>` if the envelope is sound.
fn sound_envelope(line: &[u8]) -> Option<&[u8]> {
    let text = line.strip_prefix(b"#")?;
    let digits = text.iter().take_while(|b| b.is_ascii_digit()).count();
    std::str::from_utf8(&text[..digits])
        .ok()?
        .parse::<u32>()
        .ok()?;
    let rest = &text[digits..];
    if !(rest.is_empty() || rest[0] == b' ' || rest[0] == b'\t') {
        return None;
    }
    let (signed, crc) = line.split_at(line.len().checked_sub(4)?);
    let hex = crc.strip_prefix(b" *")?;
    let found = u8::from_str_radix(std::str::from_utf8(hex).ok()?, 16).ok()?;
    (hex.iter().all(u8::is_ascii_hexdigit) && found == checksum(signed))
        .then(|| &signed[1 + digits..])
}

/// A reply is UTF-8, one line ending in CR LF, at most [`REPLY`] bytes.
fn check_reply_shape(reply: &[u8]) -> &str {
    assert!(reply.len() <= REPLY, "reply of {} bytes", reply.len());
    let text = std::str::from_utf8(reply).expect("reply is UTF-8");
    let body = text.strip_suffix("\r\n").expect("reply ends in CR LF");
    assert!(
        !body.contains(['\r', '\n']) && !body.chars().any(char::is_control),
        "a line break or control character inside {body:?}"
    );
    assert!(
        body.starts_with("ok") || body.starts_with("err ") || body.starts_with('#'),
        "verdict of {body:?}"
    );
    body
}

/// A machine-mode reply: `#<seq> <verdict …> *<crc>`, or `err line … *<crc>`
/// when the sequence number was unreadable, with a valid crc. Returns the
/// verdict part.
fn check_machine_reply(text: &str) -> &str {
    let (signed, crc) = text
        .rsplit_once(" *")
        .expect("machine reply has a checksum");
    assert_eq!(
        u8::from_str_radix(crc, 16).ok(),
        Some(checksum(signed.as_bytes())),
        "checksum of {text:?}"
    );
    let Some(numbered) = signed.strip_prefix('#') else {
        assert!(signed.starts_with("err line "), "{text:?}");
        return signed;
    };
    let (seq, verdict) = numbered.split_once(' ').expect("sequence number");
    seq.parse::<u32>().expect("decimal sequence number");
    verdict
}

/// A handler that accepts every command and replies with its debug form
/// twice (long enough to exercise truncation), counting what it saw.
#[derive(Debug, Default)]
pub struct Recorder {
    /// Commands carried out.
    pub commands: usize,
    /// Lines rejected, by kind.
    pub rejected_line: usize,
    /// Machine-mode envelopes rejected.
    pub rejected_envelope: usize,
    /// Lines the parser rejected.
    pub rejected_parse: usize,
}

impl Handler for Recorder {
    fn command(&mut self, command: Command, reply: &mut Reply<'_>) {
        use std::fmt::Write as _;
        self.commands += 1;
        write!(reply.ok(), "{command:?} {command:?}").unwrap();
    }

    fn rejected(&mut self, error: &InputError) {
        match error {
            InputError::Line(_) => self.rejected_line += 1,
            InputError::Envelope(_) => self.rejected_envelope += 1,
            InputError::Parse(_) => self.rejected_parse += 1,
        }
    }
}
