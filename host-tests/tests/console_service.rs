//! The console service on a simulated head: what each command does, and
//! the fuzz: over a million random and mutated lines, and random byte
//! streams, through the service into a head that plays a frame between
//! lines. Exactly one reply per line, no panic, and the head never leaves
//! the limits its calibration has at that frame.
//!
//! `cargo test --release console_service:: -- --nocapture` prints
//! the figures.

use std::panic::{AssertUnwindSafe, catch_unwind};

use host_tests::console::head::{SimFrames, service, shared};
use host_tests::console::{LINE, REPLY, count_line_ends, random_line, random_stream, rng};
use idle_head_core::behaviour::Applied;
use idle_head_core::console::{ErrorCode, Response, Session, outcome_reply, parse, respond};
use idle_head_core::settings::{FlashFailed, SettingsStorage, StorageError};
use proptest::prelude::RngExt as _;

use host_tests::console::talk::SimConsole as Console;

#[test]
fn every_command_does_what_it_says() {
    let mut c = Console::new();

    let r = c.say("help\nstatus");
    assert!(r[0].starts_with("ok commands: help status"), "{r:?}");
    assert!(
        r[1].starts_with("ok mode=running mdeg=")
            && r[1].contains(" us=")
            && r[1].contains(" faults=0,0,0 off=0 uptime_ms=0 fw=0.1.0 dmx=lost settings=defaults"),
        "{}",
        r[1]
    );
    // Motion goes through the queue, and the reply says what the frame
    // task started; a refused one says why.
    let r = c.say("nod\nlook 5000 -12000\nnod 90000\ncenter");
    assert!(r[0].starts_with("ok nod amp_mdeg="), "{}", r[0]);
    assert!(
        r[1].starts_with("ok look pitch=5000 yaw=-12000 ms="),
        "{}",
        r[1]
    );
    assert!(r[2].starts_with("err limit "), "{}", r[2]);
    assert!(r[3].starts_with("ok center ms="), "{}", r[3]);
    // Gestures faster than their layers free up: the head refuses, and
    // the console says so (with the time to try again).
    let r = c.say("shake\nnod\ntilt\nnod");
    assert!(
        r.iter()
            .any(|r| r.starts_with("err busy gestures: every layer is busy; try again in ")),
        "{r:?}"
    );
    assert_eq!(c.frames.refused, c.frames.refusals_told);
    // Servo: show, change, invalid, past the limits.
    let r = c.say(
        "servo yaw\nservo yaw neutral 1520\nservo yaw min 2600\nservo pitch limits -1000 1000",
    );
    assert_eq!(
        r[0],
        "ok yaw neutral=1500 per-degree=11111 direction=normal min=1000 max=2000 limits=-9000,9000"
            .replace("limits=-9000,9000", &r[0][r[0].find("limits=").unwrap()..])
    );
    assert_eq!(r[1], "ok");
    assert!(
        r[2].starts_with("err invalid yaw servo: min_pulse 2600"),
        "{}",
        r[2]
    );
    assert!(
        r[3].starts_with("err limit the head would go past the new limits"),
        "{}",
        r[3]
    );
    assert_eq!(c.frames.calibrations, 1);
    assert_eq!(c.frames.config().servos[2].neutral.0, 1520);
    let r = c.say("status");
    assert!(r[0].contains(" settings=changed "), "{}", r[0]);
    // Seeds.
    let r = c.say("seed 42\nseed random");
    assert_eq!(r[0], "ok seed=42");
    assert!(r[1].starts_with("ok seed="));
    assert!(c.link.take_seeds().is_some());
    // Save, change, load, defaults.
    let r =
        c.say("save\nstatus\nservo yaw neutral 1480\nload\nservo yaw\ndefaults\nservo yaw\nstatus");
    assert_eq!(r[0], "ok");
    assert!(r[1].contains(" settings=flash "), "{}", r[1]);
    assert_eq!(r[3], "ok");
    assert!(r[4].contains("neutral=1520"), "{}", r[4]);
    assert!(r[6].contains("neutral=1500"), "{}", r[6]);
    assert!(r[7].contains(" settings=defaults "), "{}", r[7]);
    assert_eq!(c.frames.config().servos[2].neutral.0, 1500);
    // Stop, and status says so (after the fade).
    assert_eq!(c.say("stop"), ["ok stopping"]);
    c.play(200);
    assert!(c.say("status")[0].starts_with("ok mode=stopped"));
    assert_eq!(c.frames.violations, 0);
}

#[test]
fn the_servo_rate_is_answered_set_saved_and_played() {
    let mut c = Console::new();
    let r = c.say(
        "servo rate
servo rate 333
servo rate
status",
    );
    assert_eq!(r[0], "ok servo rate=50 period_us=20000");
    assert_eq!(r[1], "ok servo rate=333 period_us=3003");
    assert_eq!(r[2], r[1]);
    assert!(
        r[3].ends_with(" settings=changed inputs=-,-,-,- seed=board rate=333"),
        "{}",
        r[3]
    );
    // The frames come 3003 µs apart from the frame after the one the rate
    // came before; the uptime counts them.
    assert_eq!(c.frames.config().frame_period.0, 3003);
    let before = c.link.status().time.0;
    c.play(1000);
    assert_eq!(c.link.status().time.0 - before, 1000 * 3003);
    // Out of the range: refused by the parser, nothing changes.
    let r = c.say(
        "servo rate 334
servo rate 49
servo rate fast",
    );
    assert!(r[0].starts_with("err range "), "{}", r[0]);
    assert!(r[1].starts_with("err range "), "{}", r[1]);
    assert!(r[2].starts_with("err syntax "), "{}", r[2]);
    assert_eq!(c.frames.config().frame_period.0, 3003);
    // Saved and loaded with the settings; `defaults` goes back to 50 Hz.
    let r = c.say(
        "save
servo rate 200
load
servo rate
defaults
servo rate",
    );
    assert_eq!(r[0], "ok");
    assert_eq!(r[3], "ok servo rate=333 period_us=3003");
    assert_eq!(r[5], "ok servo rate=50 period_us=20000");
    c.play(2);
    assert_eq!(c.frames.config().frame_period.0, 20_000);
    // Motion plays on through every change, within the limits.
    let r = c.say(
        "servo rate 250
nod
look 5000 9000
servo rate 60
shake",
    );
    assert_eq!(r[0], "ok servo rate=250 period_us=4000");
    assert_eq!(r[3], "ok servo rate=60 period_us=16667");
    c.play(300);
    assert_eq!(c.frames.violations, 0);
}

#[test]
fn new_servo_limits_reach_the_gestures_and_the_looks() {
    let mut c = Console::new();
    // Built in, pitch may go -12°..20°: a 22° nod is too much, and a look
    // at 30° is clamped to 20°, as the reply says.
    let r = c.say("nod 22000 2000\nlook 30000 0 400 hold=stay");
    assert!(r[0].starts_with("err limit nod amplitude 22°"), "{}", r[0]);
    assert_eq!(r[1], "ok look pitch=20000 yaw=0 ms=400 hold=stay clamped");
    let Some(Applied::Look(look)) = c.frames.last_applied else {
        panic!("{:?}", c.frames.last_applied)
    };
    assert!(look.clamped && look.pitch.millidegrees() == 20_000);
    // Wider limits: the 22° nod the console now accepts is played, not
    // refused by the head, and a look goes as far as the new limits.
    let r = c.say("center 400\nservo pitch limits -25000 25000\nnod 22000 1500 cycles=1");
    assert_eq!(
        r,
        [
            "ok center ms=400",
            "ok",
            "ok nod amp_mdeg=22000 ms=1500 cycles=1 intensity=50"
        ]
    );
    c.play(150);
    assert!(matches!(c.frames.last_applied, Some(Applied::Gesture(_))));
    let r = c.say("look 30000 0 400 hold=stay\nlook 24000 0 400 hold=stay");
    assert_eq!(
        r,
        [
            "ok look pitch=25000 yaw=0 ms=400 hold=stay clamped",
            "ok look pitch=24000 yaw=0 ms=400 hold=stay"
        ]
    );
    // Narrower again: a look is clamped to where the servo may go now.
    let r = c.say("center 400\nservo pitch limits -12000 15000\nlook 18000 0 400 hold=stay");
    assert_eq!(
        r,
        [
            "ok center ms=400",
            "ok",
            "ok look pitch=15000 yaw=0 ms=400 hold=stay clamped"
        ]
    );
    let Some(Applied::Look(look)) = c.frames.last_applied else {
        panic!("{:?}", c.frames.last_applied)
    };
    assert_eq!((look.clamped, look.pitch.millidegrees()), (true, 15_000));
    assert_eq!(
        c.frames.refused, 0,
        "every action the console accepted was played"
    );
    assert_eq!(c.frames.violations, 0);
}

#[test]
fn a_full_queue_is_busy_and_nothing_is_dropped() {
    let (queue, link) = shared();
    let mut frames = SimFrames::new();
    let mut svc = service(queue, link);
    let mut out = [0; REPLY];
    let (mut queued, mut busy) = (0, 0);
    for _ in 0..20 {
        match respond(Ok(b"idle amp 50"), &mut svc, &mut out) {
            Response::Later(_) => queued += 1,
            Response::Now(r) if r.starts_with(b"err busy ") => busy += 1,
            Response::Now(r) => panic!("{}", String::from_utf8_lossy(r)),
        }
    }
    assert_eq!((queued, busy), (8, 12), "the queue holds 8");
    for _ in 0..4 {
        frames.frame(queue, link);
    }
    assert_eq!(frames.applied, 8, "every accepted action was played");
    assert!(queue.is_empty());
}

#[test]
fn storage_errors_are_replies() {
    struct Broken;
    impl SettingsStorage for Broken {
        fn save(&mut self, _: &idle_head_core::settings::Settings) -> Result<(), StorageError> {
            Err(StorageError::Flash(FlashFailed))
        }
        fn load(&mut self) -> Result<idle_head_core::settings::Settings, StorageError> {
            Err(StorageError::Older { found: 0 })
        }
    }
    let (queue, link) = shared();
    let mut svc = idle_head_core::console::ConsoleService::with_defaults(queue, link, Broken);
    let mut out = [0; REPLY];
    assert_eq!(
        respond(Ok(b"save"), &mut svc, &mut out).now(),
        Some(&b"err storage save: the flash failed\r\n"[..])
    );
    assert_eq!(
        respond(Ok(b"load"), &mut svc, &mut out).now(),
        Some(&b"err storage load: stored settings are of older version 0\r\n"[..])
    );
    let mut ram = service(queue, link);
    assert_eq!(
        respond(Ok(b"load"), &mut ram, &mut out).now(),
        Some(&b"err storage load: no settings saved\r\n"[..])
    );
}

/// Lines straight to the service (as a session hands them over), with
/// 0 to 2 frames after each.
const LINES: usize = 1_100_000;
const STREAMS: u64 = 8;
const STREAM_BYTES: usize = 128 * 1024;

/// Codes a command the parser accepted may still get.
const AFTER_PARSE: [ErrorCode; 5] = [
    ErrorCode::Busy,
    ErrorCode::Limit,
    ErrorCode::Invalid,
    ErrorCode::Range,
    ErrorCode::Storage,
];

#[test]
fn a_million_lines_drive_a_head_that_stays_within_its_limits() {
    let (queue, link) = shared();
    let mut frames = SimFrames::new();
    let mut svc = service(queue, link);
    let mut rng = rng(0x5e41_11ce);
    let mut out = [0; REPLY];
    let (mut ok, mut err, mut refused_after_parse, mut panics) = (0_usize, 0_usize, 0_usize, 0);
    let (mut waited, mut told) = (0_u64, 0_u64);
    for _ in 0..LINES {
        let (_, line) = random_line(&mut rng);
        // A line holds no line end (the framer splits there).
        let line: Vec<u8> = line
            .into_iter()
            .filter(|b| *b != b'\n' && *b != b'\r')
            .collect();
        let run = catch_unwind(AssertUnwindSafe(|| {
            let reply = match respond(Ok(&line), &mut svc, &mut out) {
                Response::Now(reply) => reply.to_vec(),
                Response::Later(later) => {
                    // As a port's console does: wait for the frame task's
                    // outcome, then answer with it.
                    let outcome = frames
                        .outcome(queue, link, 0, later.ticket())
                        .expect("the frame task answers within a few frames");
                    waited += 1;
                    let reply = later
                        .finish(&mut out, |r| outcome_reply(r, &outcome.result))
                        .to_vec();
                    if outcome.result.is_err() {
                        // The head refused it: the console says so.
                        assert!(reply.starts_with(b"err busy "), "{outcome:?}");
                        told += 1;
                    } else {
                        assert!(reply.starts_with(b"ok "), "{outcome:?}");
                    }
                    reply
                }
            };
            check_verdict(&line, &reply)
        }));
        match run {
            Ok(Verdict::Ok) => ok += 1,
            Ok(Verdict::Err) => err += 1,
            Ok(Verdict::Refused) => {
                err += 1;
                refused_after_parse += 1;
            }
            Err(_) => {
                panics += 1;
                eprintln!("panic on {:?}", String::from_utf8_lossy(&line));
            }
        }
        for _ in 0..rng.random_range(0..3) {
            frames.frame(queue, link);
        }
    }
    println!(
        "service: {LINES} lines, {ok} ok, {err} err ({refused_after_parse} parsed but refused: \
         busy, limit, invalid, range, storage), panics = {panics}; head: {} frames, {} actions \
         played, {} refused by the mixer ({} not for a busy layer; {told} replies said so, \
         {waited} replies waited for the frame task), {} calibrations applied, \
         {} limit violations",
        frames.frames,
        frames.applied,
        frames.refused,
        frames.refused_not_busy,
        frames.calibrations,
        frames.violations
    );
    assert_eq!(panics, 0);
    assert_eq!(ok + err, LINES, "one reply per line");
    assert_eq!(frames.violations, 0);
    assert_eq!(
        frames.refused_not_busy, 0,
        "the head refuses only what depends on what plays (a busy layer)"
    );
    assert_eq!(
        told, frames.refused,
        "the console says so each time the head refuses"
    );
    // A busy layer is rare (5 to 10 in the streams seen: the count moves
    // with the fuzz's vocabulary); that they happen and are all told is
    // the point.
    assert!(told > 0, "refusals happen, and are told: {told}");
    assert!(frames.applied > 10_000 && frames.calibrations > 100 && refused_after_parse > 1000);
}

#[test]
fn random_streams_through_a_session_into_the_head() {
    let (queue, link) = shared();
    let mut frames = SimFrames::new();
    let mut svc = service(queue, link);
    let (mut lines, mut replies, mut bytes) = (0, 0, 0);
    for seed in 0..STREAMS {
        let mut rng = rng(0x0005_7ea0 + seed);
        let stream = random_stream(&mut rng, STREAM_BYTES);
        bytes += stream.len();
        let mut session = Session::<LINE, REPLY>::new();
        let mut got = 0;
        let mut rest = &stream[..];
        while !rest.is_empty() {
            let n = rng.random_range(1..=rest.len().min(64));
            let (chunk, tail) = rest.split_at(n);
            for &byte in chunk {
                let mut check = |r: &[u8]| {
                    assert!(r.ends_with(b"\r\n") && r.len() <= REPLY);
                    got += 1;
                };
                if let Some(r) = session.push(byte, &mut svc) {
                    check(r);
                }
                if let Some(r) = frames.finish(&mut session, queue, link, 0) {
                    check(r);
                }
            }
            frames.frame(queue, link);
            rest = tail;
        }
        assert_eq!(got, count_line_ends(&stream), "stream {seed}");
        lines += count_line_ends(&stream);
        replies += got;
    }
    println!(
        "service streams: {STREAMS} streams, {bytes} bytes, {lines} lines, {replies} replies; \
         {} frames, {} limit violations",
        frames.frames, frames.violations
    );
    assert_eq!(lines, replies);
    assert_eq!(frames.violations, 0);
}

enum Verdict {
    Ok,
    Err,
    /// Parsed, then refused by the service.
    Refused,
}

/// The reply agrees with the parser: a parse error gets its code; a
/// command gets `ok` or one of the service's codes.
fn check_verdict(line: &[u8], reply: &[u8]) -> Verdict {
    let text = std::str::from_utf8(reply).expect("UTF-8 reply");
    let body = text.strip_suffix("\r\n").expect("CR LF");
    assert!(!body.contains(['\r', '\n']), "{body:?}");
    if line.first() == Some(&b'#') {
        // Machine mode: the session's envelope (tested in console_fuzz).
        return if body.starts_with("err line ") {
            Verdict::Err
        } else {
            assert!(body.starts_with('#'), "{body:?}");
            Verdict::Ok
        };
    }
    match parse(line) {
        Err(e) => {
            assert!(body.starts_with(&format!("err {} ", e.code())), "{body:?}");
            Verdict::Err
        }
        Ok(_) if body == "ok" || body.starts_with("ok ") => Verdict::Ok,
        Ok(command) => {
            assert!(
                AFTER_PARSE
                    .iter()
                    .any(|c| body.starts_with(&format!("err {} ", c.as_str()))),
                "{command:?} → {body:?}"
            );
            Verdict::Refused
        }
    }
}

/// `status` with every field at its widest (angles and pulses past any
/// calibration, counters at their ends, the longest mode and seed) fits a
/// port's reply whole: no `…`.
#[test]
fn the_widest_status_fits_a_reply() {
    use idle_head_core::console::{HeadMode, HeadStatus, PORT_REPLY};
    use idle_head_core::{Angle, Microseconds, Timestamp};
    let mut c = Console::new();
    c.say("seed 4294967295\nservo rate 333\ninput 2 button nod\ninput 3 button nod\ninput 4 button nod\ninput 5 button nod");
    c.link.publish(HeadStatus {
        frame: u64::MAX,
        time: Timestamp(u64::MAX),
        mode: HeadMode::Stopping,
        angles: [Angle::from_millidegrees(i32::MIN); 3],
        pulses: [Microseconds(u32::MAX); 3],
        faults: [u32::MAX; 3],
        disabled: [true; 3],
        track: None,
        idle: None,
    });
    let status = c.say("status").remove(0);
    assert!(!status.contains('…'), "{status}");
    assert!(status.ends_with(" seed=4294967295 rate=333"), "{status}");
    assert!(status.len() + 2 <= PORT_REPLY, "{} bytes", status.len() + 2);
}
