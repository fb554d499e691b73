//! The telemetry's pacing (`watch`) and when it stops; a port's lines and
//! their replies through [`serve`].

use std::collections::VecDeque;

use embassy_time::{Duration, Instant};
use idle_head_core::command::Command;
use idle_head_core::console::{ConsoleLink, DualSession, Reply};

use super::{Gone, Place, Port, Received, Watch, serve, telemetry_rate};

fn ms(ms: u64) -> Instant {
    Instant::from_millis(ms)
}

/// Port `port` on `link`, at 50 frames a second.
fn place(link: &ConsoleLink, port: u8) -> Place<'_> {
    Place {
        port,
        link,
        frame: Duration::from_millis(20),
    }
}

/// The times (ms) at which lines go out at `rate` lines a second over
/// `span` ms, the port looking every `step` ms (a frame, say) and writing
/// as soon as a line is due; each write takes `write` ms.
fn lines(watch: &mut Watch, rate: u8, span: u64, step: u64, write: u64) -> Vec<u64> {
    let mut sent = Vec::new();
    let mut t = 0;
    while t < span {
        if let Some(at) = watch.due(rate, ms(t))
            && at <= ms(t)
        {
            sent.push(t);
            t += write;
            watch.sent(rate, ms(t));
        }
        t += step;
    }
    sent
}

#[test]
fn a_line_per_period_asked_for_not_per_frame() {
    for (rate, expected) in [(1_u8, 2_usize), (5, 10), (10, 20), (50, 100)] {
        let mut watch = Watch::default();
        // Woken every millisecond (far more often than frames come).
        let times = lines(&mut watch, rate, 2000, 1, 0);
        assert_eq!(times.len(), expected, "{rate} Hz over 2 s: {times:?}");
        let period = 1000 / u64::from(rate);
        for pair in times.windows(2) {
            assert_eq!(pair[1] - pair[0], period, "{rate} Hz");
        }
        assert_eq!(watch.lost, 0);
    }
}

#[test]
fn a_port_woken_every_frame_still_sends_at_its_rate() {
    let mut watch = Watch::default();
    // 20 ms frames, 2 lines a second: one line every 25 frames.
    let times = lines(&mut watch, 2, 3000, 20, 0);
    assert_eq!(times, [0, 500, 1000, 1500, 2000, 2500]);
}

#[test]
fn off_is_no_line_and_a_new_rate_starts_at_once() {
    let mut watch = Watch::default();
    assert_eq!(watch.due(0, ms(10)), None);
    assert_eq!(watch.due(4, ms(20)), Some(ms(20)), "the first line at once");
    watch.sent(4, ms(20));
    assert_eq!(watch.due(4, ms(30)), Some(ms(270)));
    // Another rate: a line at once, then at the new period.
    assert_eq!(watch.due(10, ms(40)), Some(ms(40)));
    watch.sent(10, ms(40));
    assert_eq!(watch.due(10, ms(50)), Some(ms(140)));
    assert_eq!(watch.due(0, ms(60)), None);
    assert_eq!(watch.due(10, ms(70)), Some(ms(70)), "on again: at once");
}

#[test]
fn ticks_missed_by_a_slow_host_are_counted_lost_not_sent_in_a_burst() {
    let mut watch = Watch::default();
    // 10 lines a second, each write held up 350 ms by the host.
    let times = lines(&mut watch, 10, 2000, 1, 350);
    for pair in times.windows(2) {
        assert!(pair[1] - pair[0] >= 350, "no burst: {times:?}");
    }
    // Every 100 ms tick is either sent or lost.
    let ticks = u64::from(watch.lost) + times.len() as u64;
    assert!((19..=21).contains(&ticks), "{ticks} ticks in 2 s");
    assert!(watch.lost >= 10);
}

#[test]
fn a_port_the_host_closed_stops_its_watch_for_good() {
    let link = ConsoleLink::new();
    let place = place(&link, 1);
    link.set_watch(0, 7);
    link.set_watch(1, 5);
    assert_eq!(telemetry_rate(true, false, place), 5);
    // DTR dropped.
    assert_eq!(telemetry_rate(false, false, place), 0);
    assert_eq!(link.watch(1), 0, "the port's watch is off");
    assert_eq!(link.watch(0), 7, "the other port's is not");
    // Opened again: still off until the host asks.
    assert_eq!(telemetry_rate(true, false, place), 0);
}

#[test]
fn a_bottango_session_has_no_telemetry_but_keeps_the_rate() {
    let link = ConsoleLink::new();
    let place = place(&link, 0);
    link.set_watch(0, 5);
    assert_eq!(telemetry_rate(true, true, place), 0);
    assert_eq!(link.watch(0), 5);
    assert_eq!(telemetry_rate(true, false, place), 5);
}

/// A port that hands out its input in the chunks given, keeps what is
/// written to it, and is gone after the last chunk.
struct Chunks {
    input: VecDeque<&'static [u8]>,
    written: Vec<u8>,
}

impl Port for Chunks {
    async fn read(&mut self, buf: &mut [u8]) -> Result<Received, Gone> {
        let chunk = self.input.pop_front().ok_or(Gone)?;
        buf[..chunk.len()].copy_from_slice(chunk);
        Ok(Received::Bytes(chunk.len()))
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Gone> {
        self.written.extend_from_slice(bytes);
        Ok(())
    }
}

#[test]
fn every_line_is_answered_once_in_order_wherever_the_reads_cut_it() {
    let link = ConsoleLink::new();
    let place = place(&link, 0);
    let mut port = Chunks {
        input: VecDeque::from([&b"stat"[..], b"us\r", b"\nhelp\r\nzz\n\nsave", b"\r\n"]),
        written: Vec::new(),
    };
    let mut seen = Vec::new();
    let mut handler = |command: Command, _: &mut Reply<'_>| seen.push(command);
    let mut session = DualSession::new(None);
    let gone = embassy_futures::block_on(serve(&mut port, &mut session, &mut handler, place));
    assert_eq!(gone, Gone);
    assert_eq!(seen, [Command::Status, Command::Help, Command::Save]);
    let written = String::from_utf8(port.written).unwrap();
    let replies: Vec<&str> = written.split_terminator("\r\n").collect();
    assert_eq!(replies.len(), 5, "{written:?}");
    assert_eq!(replies[..2], ["ok", "ok"], "{written:?}");
    assert!(replies[2].starts_with("err syntax"), "{written:?}");
    assert!(replies[3].starts_with("err"), "an empty line: {written:?}");
    assert_eq!(replies[4], "ok", "{written:?}");
}
