//! One conversation with a head, over any port: the bytes of the input go
//! to the port as they are (no decoding: a line that is not UTF-8 reaches
//! the head, which answers it with an error), each reply line comes back as
//! bytes, and the replies are counted against the lines sent, which are
//! counted as the head's own framer ends them.

use std::{
    io::{ErrorKind, Read, Write},
    sync::atomic::{AtomicBool, AtomicUsize, Ordering},
    thread,
    time::{Duration, Instant},
};

use anyhow::Result;
use idle_head_core::console::Framer;

/// Counts the lines of a byte stream where the head's framer ends them (CR,
/// LF or CR LF), so that the replies due are known whatever the line ends.
#[derive(Debug, Default)]
pub struct LineEnds {
    /// Capacity 0: only its line ends are of use here, and every line end
    /// yields exactly one outcome, however long the line.
    framer: Framer<0>,
    lines: usize,
    /// Bytes after the last line end: a line in progress.
    open: bool,
    /// The last byte was a CR (a following LF ends no second line).
    after_cr: bool,
}

impl LineEnds {
    /// Takes a run of bytes.
    pub fn feed(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            if self.framer.push(byte).is_some() {
                self.lines += 1;
                self.open = false;
            } else if !(byte == b'\n' && self.after_cr) {
                self.open = true;
            }
            self.after_cr = byte == b'\r';
        }
    }

    /// Lines ended so far.
    pub fn lines(&self) -> usize {
        self.lines
    }

    /// Whether bytes follow the last line end.
    pub fn open(&self) -> bool {
        self.open
    }
}

/// How a conversation went.
#[derive(Debug)]
pub struct Talk {
    pub sent: usize,
    pub replies: usize,
    /// What ended the conversation before its end, if anything did.
    pub early: Option<String>,
}

impl Talk {
    /// Lines that got no reply.
    pub fn missing(&self) -> usize {
        self.sent.saturating_sub(self.replies)
    }

    /// What went wrong, one sentence each: an early end, missing replies.
    pub fn problems(&self) -> Vec<String> {
        let mut problems: Vec<String> = self.early.iter().cloned().collect();
        if self.missing() > 0 {
            problems.push(format!(
                "{} of {} lines got no reply",
                self.missing(),
                self.sent
            ));
        }
        problems
    }
}

/// Splits `reader`'s bytes into reply lines (their CR LF or LF taken off),
/// handed to `each`, until the stream ends (`Ok`), a read fails (`Err`), or
/// `stop` is set (checked when a read times out).
pub fn read_replies(
    mut reader: impl Read,
    stop: &AtomicBool,
    mut each: impl FnMut(&[u8]),
) -> std::io::Result<()> {
    let mut line = Vec::new();
    let mut buf = [0_u8; 4096];
    loop {
        match reader.read(&mut buf) {
            Ok(0) => return Ok(()),
            Ok(n) => {
                for &b in &buf[..n] {
                    if b == b'\n' {
                        if line.last() == Some(&b'\r') {
                            line.pop();
                        }
                        each(&line);
                        line.clear();
                    } else {
                        line.push(b);
                    }
                }
            }
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {
                if stop.load(Ordering::Acquire) {
                    return Ok(());
                }
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
}

/// The conversation: this thread sends `input` to `port` as it comes, byte
/// for byte (a last line without a line end gets an LF, so that it is
/// answered); a reader thread hands each reply line read from `replies` to
/// `on_reply`. Once the input ends, it waits up to `wait` for the replies
/// still due, then calls `hang_up`, after which the reader must end: at the
/// end of `replies`, or at its next read timeout. Nothing ends it silently:
/// a failed read of the input, a failed write to the port, and the port
/// closing before the hang-up are [`Talk::early`].
pub fn converse(
    mut input: impl Read,
    port: &mut impl Write,
    replies: impl Read + Send,
    on_reply: &mut (impl FnMut(&[u8]) + Send),
    wait: Duration,
    hang_up: impl FnOnce() -> Result<()>,
) -> Talk {
    let received = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let mut ends = LineEnds::default();
    let mut early = None;
    thread::scope(|scope| {
        let (received, stop) = (&received, &stop);
        let reading = scope.spawn(move || {
            let end = read_replies(replies, stop, |reply| {
                on_reply(reply);
                received.fetch_add(1, Ordering::AcqRel);
            });
            // Before the hang-up, the port must not end.
            match end {
                Err(e) => Some(format!("reading the port failed: {e}")),
                Ok(()) if !stop.load(Ordering::Acquire) => Some("the port closed".to_owned()),
                Ok(()) => None,
            }
        });
        let mut buf = [0_u8; 4096];
        loop {
            let n = match input.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => n,
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(e) => {
                    early = Some(format!("reading the input failed: {e}"));
                    break;
                }
            };
            if let Err(e) = port.write_all(&buf[..n]).and_then(|()| port.flush()) {
                early = Some(format!("writing to the port failed: {e}"));
                break;
            }
            ends.feed(&buf[..n]);
            if reading.is_finished() {
                break;
            }
        }
        if early.is_none() && ends.open() {
            match port.write_all(b"\n").and_then(|()| port.flush()) {
                Ok(()) => ends.feed(b"\n"),
                Err(e) => early = Some(format!("writing to the port failed: {e}")),
            }
        }
        let deadline = Instant::now() + wait;
        while received.load(Ordering::Acquire) < ends.lines()
            && Instant::now() < deadline
            && !reading.is_finished()
        {
            thread::sleep(Duration::from_millis(2));
        }
        stop.store(true, Ordering::Release);
        let hang_up_result = hang_up();
        let why = reading
            .join()
            .unwrap_or_else(|_| Some("the reader of the port panicked".to_owned()));
        // The first thing that went wrong is the one to report.
        early = early.take().or(why).or_else(|| {
            hang_up_result
                .err()
                .map(|e| format!("hanging up failed: {e:#}"))
        });
        Talk {
            sent: ends.lines(),
            replies: received.load(Ordering::Acquire),
            early,
        }
    })
}

#[cfg(test)]
mod tests {
    use std::os::unix::net::UnixStream;

    use super::*;

    #[test]
    fn lines_end_where_the_heads_framer_ends_them() {
        let count = |bytes: &[u8]| {
            let mut ends = LineEnds::default();
            // Split anywhere, it counts the same.
            for chunk in bytes.chunks(1) {
                ends.feed(chunk);
            }
            (ends.lines(), ends.open())
        };
        assert_eq!(count(b""), (0, false));
        assert_eq!(count(b"help\nnod \xff\nstatus\n"), (3, false));
        assert_eq!(count(b"a\r\nb\rc\n\n"), (4, false));
        assert_eq!(count(b"a\r\n"), (1, false));
        assert_eq!(count(b"a\nstat"), (1, true));
        assert_eq!(count(b"a\n\x7f"), (1, true));
    }

    /// A head on the other end of a socket: one reply per line (ended by
    /// CR, LF or CR LF), the line's bytes echoed after `got ` (so a 0xff
    /// comes back as it went); at `quit`, it closes the socket without a
    /// reply.
    fn echo_head(mut stream: UnixStream) {
        let mut buf = [0_u8; 256];
        let mut line = Vec::new();
        let mut after_cr = false;
        while let Ok(n @ 1..) = stream.read(&mut buf) {
            let mut replies = Vec::new();
            for &b in &buf[..n] {
                let end = b == b'\r' || (b == b'\n' && !after_cr);
                after_cr = b == b'\r';
                if !end {
                    line.extend((b != b'\n').then_some(b));
                    continue;
                }
                if line == b"quit" {
                    let _ = stream.write_all(&replies);
                    return;
                }
                replies.extend_from_slice(b"got ");
                replies.append(&mut line);
                replies.extend_from_slice(b"\r\n");
            }
            if stream.write_all(&replies).is_err() {
                return;
            }
        }
    }

    fn talk(input: &[u8]) -> (Vec<Vec<u8>>, Talk) {
        let (mut ours, theirs) = UnixStream::pair().unwrap();
        let head = thread::spawn(move || echo_head(theirs));
        let reader = ours.try_clone().unwrap();
        let mut got = Vec::new();
        let hang_up = ours.try_clone().unwrap();
        let talk = converse(
            input,
            &mut ours,
            reader,
            &mut |reply: &[u8]| got.push(reply.to_vec()),
            Duration::from_secs(5),
            || Ok(hang_up.shutdown(std::net::Shutdown::Both)?),
        );
        head.join().unwrap();
        (got, talk)
    }

    #[test]
    fn bytes_go_through_unchanged_both_ways() {
        let (got, talk) = talk(b"help\nnod \xff\n\xc3\xa9\rstatus");
        assert_eq!(
            got,
            [
                b"got help".to_vec(),
                b"got nod \xff".to_vec(),
                b"got \xc3\xa9".to_vec(),
                // The last line had no line end: it got one.
                b"got status".to_vec(),
            ]
        );
        assert_eq!((talk.sent, talk.replies), (4, 4));
        assert!(talk.problems().is_empty(), "{:?}", talk.problems());
    }

    #[test]
    fn a_port_that_closes_early_is_reported() {
        let (got, talk) = talk(b"one\nquit\ntwo\n");
        assert_eq!(got, [b"got one".to_vec()]);
        assert_eq!(talk.early.as_deref(), Some("the port closed"));
        assert_eq!(talk.missing(), 2);
        assert_eq!(
            talk.problems(),
            ["the port closed", "2 of 3 lines got no reply"]
        );
    }

    /// Input that fails after its first line.
    struct Broken(bool);

    impl Read for Broken {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            if std::mem::replace(&mut self.0, true) {
                return Err(std::io::Error::other("the disk is on fire"));
            }
            buf[..5].copy_from_slice(b"help\n");
            Ok(5)
        }
    }

    #[test]
    fn an_input_that_fails_is_reported_and_what_was_sent_is_answered() {
        let (mut ours, theirs) = UnixStream::pair().unwrap();
        let head = thread::spawn(move || echo_head(theirs));
        let reader = ours.try_clone().unwrap();
        let hang_up = ours.try_clone().unwrap();
        let mut replies = 0;
        let talk = converse(
            Broken(false),
            &mut ours,
            reader,
            &mut |_: &[u8]| replies += 1,
            Duration::from_secs(5),
            || Ok(hang_up.shutdown(std::net::Shutdown::Both)?),
        );
        head.join().unwrap();
        assert_eq!((talk.sent, talk.replies, replies), (1, 1, 1));
        assert_eq!(
            talk.early.as_deref(),
            Some("reading the input failed: the disk is on fire")
        );
    }
}
