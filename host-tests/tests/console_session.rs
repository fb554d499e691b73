//! The console's line framer and session, case by case: line ends,
//! editing, bad lines, replies, machine mode.

use std::fmt::Write as _;

use idle_head_core::command::{Action, Command};
use idle_head_core::console::{
    EnvelopeError, ErrorCode, Framer, Handler, InputError, LineError, MIN_REPLY, Reply, Session,
    checksum, parse, respond,
};

type Outcome = Result<Vec<u8>, LineError>;

/// The outcomes of `pieces` fed one after another to one framer.
fn frame<const N: usize>(pieces: &[&[u8]]) -> Vec<Outcome> {
    let mut framer = Framer::<N>::new();
    let mut out = Vec::new();
    for piece in pieces {
        framer.feed(piece, |line| out.push(line.map(<[u8]>::to_vec)));
    }
    out
}

fn ok(line: &str) -> Outcome {
    Ok(line.as_bytes().to_vec())
}

#[test]
fn line_ends_of_every_terminal() {
    assert_eq!(frame::<16>(&[b"a\rb\nc\r\nd"]), [ok("a"), ok("b"), ok("c")]);
    // CR and LF of one CR LF in separate reads: one line end.
    assert_eq!(
        frame::<16>(&[b"help\r", b"\nstop\r", b"", b"\n"]),
        [ok("help"), ok("stop")]
    );
    // LF CR and CR CR are two ends: the second line is empty.
    assert_eq!(
        frame::<16>(&[b"a\n\rb\r\r"]),
        [ok("a"), ok(""), ok("b"), ok("")]
    );
    // A line of blanks is a line.
    assert_eq!(frame::<16>(&[b" \t \n"]), [ok(" \t ")]);
    // Bytes after the last end are not a line yet.
    assert_eq!(frame::<16>(&[b"status"]), []);
}

#[test]
fn backspace_and_del_edit_the_line() {
    assert_eq!(frame::<16>(&[b"nox\x08d\r"]), [ok("nod")]);
    assert_eq!(
        frame::<16>(&[b"\x7f\x08stop\x7f\x7f\x7fhelp\n"]),
        [ok("shelp")]
    );
    // A whole multi-byte character at a time.
    assert_eq!(frame::<16>(&["a€😀\x7f\x7fb\n".as_bytes()]), [ok("ab")]);
    // A stray byte goes alone.
    assert_eq!(
        frame::<16>(&[b"a\x80\x80\x08\n"]),
        [Err(LineError::NotUtf8 { at: 1 })]
    );
    // A control byte typed by mistake and deleted leaves no trace.
    assert_eq!(frame::<16>(&[b"stat\x1b\x7fus\n"]), [ok("status")]);
}

#[test]
fn bad_lines_are_reported_once_each() {
    assert_eq!(
        frame::<8>(&[b"12345678\n123456789\n"]),
        [ok("12345678"), Err(LineError::TooLong { len: 9, max: 8 })]
    );
    // Discarded up to the end, across reads; backspace does not bring it back.
    assert_eq!(
        frame::<8>(&[b"123456789", b"0123\x7f\x7f\x7f\x7f\x7f", b"\r\nnod\n"]),
        [Err(LineError::TooLong { len: 18, max: 8 }), ok("nod")]
    );
    // Full, then edited back before overflowing: fine.
    assert_eq!(frame::<4>(&[b"abcd\x08e\n"]), [ok("abce")]);
    assert_eq!(
        frame::<16>(&[b"seed\x001\n", b"look\x1b[A\n"]),
        [
            Err(LineError::Control { at: 4, byte: 0 }),
            Err(LineError::Control { at: 4, byte: 0x1b })
        ]
    );
    assert_eq!(
        frame::<16>(&[b"nod \xe2\x82\n", b"\xff\n"]),
        [
            Err(LineError::NotUtf8 { at: 4 }),
            Err(LineError::NotUtf8 { at: 0 })
        ]
    );
    // The control byte is found before the UTF-8 check.
    assert_eq!(
        frame::<16>(&[b"\xff\x01\n"]),
        [Err(LineError::Control { at: 1, byte: 1 })]
    );
}

/// Replies as text, from one session fed `input` in one go.
fn session(input: &[u8], handler: &mut impl Handler) -> Vec<String> {
    let mut session = Session::<32, 80>::new();
    let mut replies = Vec::new();
    session.feed(input, handler, |r| {
        replies.push(String::from_utf8(r.to_vec()).unwrap());
    });
    replies
}

/// Carries out nothing; counts what it hears.
#[derive(Default)]
struct Counter {
    commands: Vec<Command>,
    rejected: Vec<InputError>,
}

impl Handler for Counter {
    fn command(&mut self, command: Command, reply: &mut Reply<'_>) {
        self.commands.push(command);
        match command {
            Command::Help => {
                reply.ok().write_str("a\r\nb\x00c").unwrap();
            }
            Command::Save => {
                write!(reply.ok(), "first").unwrap();
                write!(reply.err(ErrorCode::Storage), "flash error {}", -5).unwrap();
            }
            Command::Load => {
                write!(reply.ok(), "{}", "0123456789".repeat(10)).unwrap();
            }
            _ => {}
        }
    }

    fn rejected(&mut self, error: &InputError) {
        self.rejected.push(*error);
    }
}

#[test]
fn one_reply_per_line() {
    let mut h = Counter::default();
    let replies = session(
        b"stop\r\n\r\nhelp\nsave\rload\n\xff\nnod 1 0\r\nthis line is longer than thirty-two bytes\n",
        &mut h,
    );
    assert_eq!(
        replies,
        [
            "ok\r\n",
            "err syntax empty line (try `help`)\r\n",
            // Line breaks and control characters never reach the wire.
            "ok a??b?c\r\n",
            // The last verdict counts.
            "err storage flash error -5\r\n",
            // Cut at the buffer (80 bytes, 9 kept for the end) and marked.
            &format!("ok {}…\r\n", &"0123456789".repeat(7)[..68]),
            "err line not UTF-8 from byte 0 on\r\n",
            "err range `0`: duration in ms must be in 1..=4294967295\r\n",
            "err line too long (41 bytes, at most 32)\r\n",
        ]
    );
    assert_eq!(
        h.commands,
        [
            Command::Act(Action::Stop),
            Command::Help,
            Command::Save,
            Command::Load
        ]
    );
    assert_eq!(h.rejected.len(), 4);
    assert!(matches!(h.rejected[0], InputError::Parse(_)));
    assert_eq!(
        h.rejected[1],
        InputError::Line(LineError::NotUtf8 { at: 0 })
    );
    assert_eq!(h.rejected[1].code(), ErrorCode::Line);
    assert_eq!(h.rejected[2].code(), ErrorCode::Range);
    assert!(replies.iter().all(|r| r.len() <= 80));
}

/// `line` in machine mode: `#<seq> <line> *<crc>`.
fn signed(seq: u32, line: &str) -> String {
    let body = format!("#{seq} {line}");
    format!("{body} *{:02x}", checksum(body.as_bytes()))
}

#[test]
fn machine_mode() {
    // The catalogue's check value of CRC-8/SMBUS.
    assert_eq!(checksum(b"123456789"), 0xf4);
    let mut h = Counter::default();
    let good = signed(17, "save");
    let upper = format!("#4294967295 stop *{:02X}", checksum(b"#4294967295 stop"));
    let replies = session(
        format!(
            "{good}\n{upper}\n#18 stop *00\n#19 stop\n#x stop *12\n#20nod *00\n{}\n",
            signed(21, "nod six")
        )
        .as_bytes(),
        &mut h,
    );
    let sign = |body: &str| format!("{body} *{:02x}\r\n", checksum(body.as_bytes()));
    let bad_crc = checksum(b"#18 stop");
    assert_eq!(
        replies,
        [
            sign("#17 err storage flash error -5"),
            sign("#4294967295 ok"),
            sign(&format!(
                "#18 err line checksum 00 does not match the line ({bad_crc:02x})"
            )),
            sign("#19 err line missing checksum (end the line with ` *<crc>`)"),
            sign("err line bad sequence number (`#<seq> <command> *<crc>`)"),
            sign("err line bad sequence number (`#<seq> <command> *<crc>`)"),
            sign("#21 err syntax `six`: amplitude in mdeg must be a whole number"),
        ]
    );
    assert_eq!(h.commands, [Command::Save, Command::Act(Action::Stop)]);
    assert_eq!(
        h.rejected[..4],
        [
            InputError::Envelope(EnvelopeError::BadChecksum {
                found: 0,
                computed: bad_crc
            }),
            InputError::Envelope(EnvelopeError::MissingChecksum),
            InputError::Envelope(EnvelopeError::BadSequence),
            InputError::Envelope(EnvelopeError::BadSequence),
        ]
    );
}

#[test]
fn a_long_machine_reply_keeps_its_checksum() {
    let mut h = Counter::default();
    let line = signed(123_456, "load");
    let mut out = [0; MIN_REPLY];
    let mut framer = Framer::<32>::new();
    let mut reply = Vec::new();
    framer.feed(format!("{line}\n").as_bytes(), |l| {
        reply = respond(l, &mut h, &mut out).now().unwrap().to_vec();
    });
    let text = String::from_utf8(reply).unwrap();
    let (signed_part, crc) = text.trim_end().rsplit_once(" *").unwrap();
    assert!(signed_part.starts_with("#123456 ok 0123") && signed_part.ends_with('…'));
    assert_eq!(
        u8::from_str_radix(crc, 16).unwrap(),
        checksum(signed_part.as_bytes())
    );
    assert_eq!(text.len(), MIN_REPLY);
}

#[test]
fn error_codes_are_one_word_each() {
    let words: Vec<&str> = ErrorCode::ALL.iter().map(|c| c.as_str()).collect();
    assert_eq!(
        words,
        [
            "syntax",
            "range",
            "line",
            "busy",
            "invalid",
            "limit",
            "storage",
            "state",
            "unavailable"
        ]
    );
    for (i, w) in words.iter().enumerate() {
        assert!(w.bytes().all(|b| b.is_ascii_lowercase()));
        assert!(!words[..i].contains(w));
    }
    let range = parse(b"idle amp 101").unwrap_err();
    assert_eq!(ErrorCode::of(&range), ErrorCode::Range);
    let syntax = parse(b"idle amp x").unwrap_err();
    assert_eq!(ErrorCode::of(&syntax).as_str(), syntax.code());
}

/// Bytes lost before the framer (a UART overrun or framing error): the
/// line they belonged to is answered as lost, never carried out as what
/// its surviving bytes spell; the lines around it are untouched.
#[test]
fn a_line_that_lost_bytes_is_answered_so() {
    let lost: Outcome = Err(LineError::Lost);
    let mut framer = Framer::<16>::new();
    // `before`, a loss, `after`: the outcomes.
    let mut around = |before: &[u8], after: &[u8]| {
        let mut out: Vec<Outcome> = Vec::new();
        framer.feed(before, |l| out.push(l.map(<[u8]>::to_vec)));
        framer.lose();
        framer.feed(after, |l| out.push(l.map(<[u8]>::to_vec)));
        out
    };
    // In the middle of a line.
    assert_eq!(
        around(b"nod\r\nsta", b"tus\r\nstatus\n"),
        [ok("nod"), lost.clone(), ok("status")]
    );
    // Right after a line end: the next line lost its first bytes. Its CR
    // LF still counts as one line end; the LF after it is an empty line.
    assert_eq!(
        around(b"nod\r\n", b"us\r\n\n"),
        [ok("nod"), lost.clone(), ok("")]
    );
    // Between a CR and its LF: the LF ends a line of its own, which lost
    // bytes (whatever came between the two is gone).
    assert_eq!(around(b"nod\r", b"\nnod\n"), [ok("nod"), lost, ok("nod")]);

    // The session: one reply per line end, the lost line not carried out.
    let mut handler = Counter::default();
    let mut session = Session::<32, 80>::new();
    let mut replies = Vec::new();
    session.feed(b"sta", &mut handler, |r| replies.push(r.to_vec()));
    session.lose();
    session.feed(b"tus\r\nstatus\r\n", &mut handler, |r| {
        replies.push(r.to_vec())
    });
    let text: Vec<String> = replies
        .iter()
        .map(|r| String::from_utf8(r.clone()).unwrap())
        .collect();
    assert_eq!(
        text,
        [
            "err line bytes lost on the way in (a receive error): send it again\r\n",
            "ok\r\n"
        ]
    );
    assert_eq!(handler.commands, [Command::Status]);
    assert_eq!(handler.rejected, [InputError::Line(LineError::Lost)]);
}

/// Numbers in replies are written as `format!` writes them, with and
/// without leading zeros, at every decimal and 32-bit boundary (the
/// digits below 2^32 take a path of their own).
#[test]
fn numbers_are_written_as_format_writes_them() {
    use idle_head_core::text::{Describe, Text, display};
    struct Zeros(u64, usize);
    impl Describe for Zeros {
        fn describe(&self, out: &mut dyn Text) {
            out.zeros(self.0, self.1);
        }
    }
    impl std::fmt::Display for Zeros {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            display(self, f)
        }
    }
    let mut values = vec![u64::from(u32::MAX), 1 << 32, (1 << 32) + 1, u64::MAX];
    for k in 0..20 {
        let p = 10_u64.pow(k);
        values.extend([p - 1, p, p + 1, p.saturating_mul(7).saturating_add(3)]);
        let big = p.saturating_mul(1_000_000_000);
        values.extend([big, big.saturating_add(1), big - 1]);
    }
    for n in values {
        for width in [1, 3, 9, 10, 18, 20] {
            assert_eq!(
                Zeros(n, width).to_string(),
                format!("{n:0width$}"),
                "{n} {width}"
            );
        }
    }
}
