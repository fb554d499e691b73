//! The console fuzzed: over a million random and mutated lines through the
//! parser, and megabytes of random byte streams through the framer and the
//! session. Nothing may panic, and every line end gets exactly one
//! well-formed reply that agrees with a reference line discipline and the
//! parser.
//!
//! `cargo test console_fuzz:: -- --nocapture` prints the figures.
//! The cases come from fixed seeds (plain loops, not proptest: shrinking
//! a million cases is not needed to find a panic, and too slow).

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};

use host_tests::console::{
    LINE, LineKind, REPLY, Recorder, ReplyCounts, check_replies, command_text, random_command,
    random_line, random_stream, reference_lines, rng, run_stream, varied_text,
};
use idle_head_core::console::{ErrorCode, Framer, LineError, parse, respond};
use proptest::prelude::RngExt as _;

/// Lines through the parser (and the reply formatting); a fifth are valid
/// commands, the rest (over a million) mutated, random words or random bytes.
const PARSER_LINES: usize = 1_300_000;
/// Random commands spelled out and parsed back.
const ROUND_TRIPS: usize = 200_000;
/// Byte streams through the framer and the session.
const STREAMS: u64 = 24;
const STREAM_BYTES: usize = 256 * 1024;

#[test]
fn a_million_lines_through_the_parser() {
    let mut rng = rng(0x00c0_ffee);
    let mut kinds: BTreeMap<String, usize> = BTreeMap::new();
    let (mut accepted, mut range, mut syntax, mut panics) = (0, 0, 0, 0);
    let mut bytes = 0;
    let mut recorder = Recorder::default();
    let mut out = [0; REPLY];
    for _ in 0..PARSER_LINES {
        let (kind, line) = random_line(&mut rng);
        bytes += line.len();
        *kinds.entry(format!("{kind:?}")).or_default() += 1;
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            check_line(&line, kind);
            // The whole reply path, for lines that fit a line buffer.
            let reply = respond(Ok(&line), &mut recorder, &mut out)
                .now()
                .expect("the recorder answers at once");
            assert!(reply.ends_with(b"\r\n") && reply.len() <= REPLY);
        }));
        match (outcome, parse(&line)) {
            (Err(_), _) => {
                panics += 1;
                eprintln!("panic on {:?}", String::from_utf8_lossy(&line));
            }
            (Ok(()), Ok(_)) => accepted += 1,
            (Ok(()), Err(e)) if ErrorCode::of(&e) == ErrorCode::Range => range += 1,
            (Ok(()), Err(_)) => syntax += 1,
        }
    }
    println!(
        "parser: {PARSER_LINES} lines ({bytes} bytes; {kinds:?}): {accepted} accepted, \
         {range} `range`, {syntax} `syntax`, panics = {panics}"
    );
    assert_eq!(panics, 0);
    assert_eq!(accepted + range + syntax, PARSER_LINES);
    // The mutations reach every outcome often.
    assert!(
        accepted > PARSER_LINES / 10 && range > PARSER_LINES / 100 && syntax > PARSER_LINES / 2
    );
}

/// What must hold for any line: a command that prints and parses back as
/// itself, or an error inside the line with a one-line reason.
fn check_line(line: &[u8], kind: LineKind) {
    match parse(line) {
        Ok(command) => {
            let canonical = command_text(&command);
            assert_eq!(parse(canonical.as_bytes()), Ok(command), "{canonical:?}");
        }
        Err(e) => {
            assert!(
                kind != LineKind::Valid,
                "valid line {:?} rejected: {}",
                String::from_utf8_lossy(line),
                e.describe(line)
            );
            assert!(e.at.start <= e.at.end && usize::from(e.at.end) <= line.len());
            assert_eq!(ErrorCode::of(&e).as_str(), e.code());
            let reason = e.describe(line).to_string();
            assert!(
                !reason.is_empty() && !reason.contains(['\r', '\n']),
                "{reason:?}"
            );
        }
    }
}

#[test]
fn every_command_reads_back_as_itself() {
    let mut rng = rng(7);
    for _ in 0..ROUND_TRIPS {
        let command = random_command(&mut rng);
        let canonical = command_text(&command);
        assert_eq!(parse(canonical.as_bytes()), Ok(command), "{canonical:?}");
        let varied = varied_text(&command, &mut rng);
        assert_eq!(parse(varied.as_bytes()), Ok(command), "{varied:?}");
    }
    println!("round trips: {ROUND_TRIPS} random commands, canonical and varied spelling");
}

#[test]
fn random_streams_through_the_framer_and_the_session() {
    let mut totals = ReplyCounts::default();
    let (mut bytes, mut panics) = (0, 0);
    let mut recorder = Recorder::default();
    for seed in 0..STREAMS {
        let mut rng = rng(0x5742_0000 + seed);
        let stream = random_stream(&mut rng, STREAM_BYTES);
        bytes += stream.len();
        let run = catch_unwind(AssertUnwindSafe(|| {
            check_framer::<LINE>(&stream, &mut rng);
            check_framer::<8>(&stream, &mut rng);
            let replies = run_stream(&stream, &mut rng, &mut recorder);
            check_replies(&stream, &replies)
        }));
        match run {
            Ok(counts) => {
                totals.lines += counts.lines;
                totals.ok += counts.ok;
                totals.err += counts.err;
                totals.truncated += counts.truncated;
                totals.machine += counts.machine;
            }
            Err(_) => {
                panics += 1;
                eprintln!("stream {seed} failed");
            }
        }
    }
    println!(
        "streams: {STREAMS} streams, {bytes} bytes, {} lines, {} replies ok, {} err \
         ({} truncated, {} machine mode); handler saw {} commands, rejected {} lines, \
         {} envelopes, {} parses; panics = {panics}",
        totals.lines,
        totals.ok,
        totals.err,
        totals.truncated,
        totals.machine,
        recorder.commands,
        recorder.rejected_line,
        recorder.rejected_envelope,
        recorder.rejected_parse,
    );
    assert_eq!(panics, 0);
    assert_eq!(totals.ok + totals.err, totals.lines);
    assert_eq!(
        recorder.commands
            + recorder.rejected_line
            + recorder.rejected_envelope
            + recorder.rejected_parse,
        totals.lines,
        "the handler hears about every line once"
    );
    // Every kind of line occurred.
    assert!(totals.truncated > 0 && totals.machine > 0 && recorder.rejected_envelope > 0);
    assert!(recorder.rejected_line > 0 && recorder.commands > totals.lines / 10);
}

/// The framer, fed in random chunks, gives the reference outcomes.
fn check_framer<const N: usize>(stream: &[u8], rng: &mut proptest::test_runner::TestRng) {
    let mut framer = Framer::<N>::new();
    let mut got: Vec<Result<Vec<u8>, LineError>> = Vec::new();
    let mut rest = stream;
    while !rest.is_empty() {
        let n = rng.random_range(1..=rest.len().min(200));
        let (chunk, tail) = rest.split_at(n);
        framer.feed(chunk, |line| got.push(line.map(<[u8]>::to_vec)));
        rest = tail;
    }
    let want = reference_lines(stream, N);
    assert_eq!(got.len(), want.len(), "line count, capacity {N}");
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert_eq!(g, w, "line {i}, capacity {N}");
    }
}
