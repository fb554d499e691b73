//! One conversation with a head over any port: bytes go as they are, both
//! ways; replies are counted against the lines the head's framer ends.

use std::{
    io::{BufRead, BufReader, ErrorKind, Read, Write},
    sync::atomic::{AtomicBool, AtomicUsize, Ordering},
    thread,
    time::{Duration, Instant},
};

use anyhow::Result;
use idle_head_core::console::Framer;

/// Counts the lines of a byte stream where the head's framer ends them (CR,
/// LF or CR LF), and whether bytes follow the last line end.
#[derive(Debug, Default)]
pub struct LineEnds {
    /// Capacity 0: every line end yields one outcome, however long the line.
    framer: Framer<0>,
    pub lines: usize,
    pub open: bool,
    /// The last byte was a CR (a following LF ends no second line).
    after_cr: bool,
}

impl LineEnds {
    pub fn feed(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            if self.framer.push(byte).is_some() {
                (self.lines, self.open) = (self.lines + 1, false);
            } else if !(byte == b'\n' && self.after_cr) {
                self.open = true;
            }
            self.after_cr = byte == b'\r';
        }
    }
}

/// How a conversation went: lines sent, replies, what ended it early.
#[derive(Debug)]
pub struct Talk {
    pub sent: usize,
    pub replies: usize,
    pub early: Option<String>,
}

impl Talk {
    /// What went wrong, one sentence each: an early end, missing replies.
    pub fn problems(&self) -> Vec<String> {
        let missing = self.sent.saturating_sub(self.replies);
        let missed = format!("{missing} of {} lines got no reply", self.sent);
        self.early
            .iter()
            .cloned()
            .chain((missing > 0).then_some(missed))
            .collect()
    }
}

/// Writes `bytes` to the port and counts their line ends.
fn send(port: &mut impl Write, ends: &mut LineEnds, bytes: &[u8]) -> Result<(), String> {
    let sent = port.write_all(bytes).and_then(|()| port.flush());
    sent.map(|()| ends.feed(bytes))
        .map_err(|e| format!("writing to the port failed: {e}"))
}

/// Hands `reader`'s lines to `each` (without CR LF or LF) until the stream
/// ends, a read fails, or `stop` is set (checked when a read times out).
fn read_replies(
    reader: impl Read,
    stop: &AtomicBool,
    mut each: impl FnMut(&[u8]),
) -> std::io::Result<()> {
    let (mut reader, mut line) = (BufReader::new(reader), Vec::new());
    loop {
        // A timed-out read keeps what it read of the line in `line`.
        match reader.read_until(b'\n', &mut line) {
            Ok(0) => return Ok(()),
            Ok(_) => {
                if let Some(reply) = line.strip_suffix(b"\n") {
                    each(reply.strip_suffix(b"\r").unwrap_or(reply));
                    line.clear();
                }
            }
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {
                if stop.load(Ordering::Acquire) {
                    return Ok(());
                }
            }
            // The other end closed with bytes of ours unread.
            Err(e) if e.kind() == ErrorKind::ConnectionReset => return Ok(()),
            Err(e) => return Err(e),
        }
    }
}

/// The conversation: `input` to `port` as it comes (an LF ends a last line
/// without one), each line of `replies` to `on_reply` from a thread; then up
/// to `wait` for the replies due, and `hang_up`, after which the reader must
/// end. A failed read or write, or the port closing first, is [`Talk::early`].
pub fn converse(
    mut input: impl Read,
    port: &mut impl Write,
    replies: impl Read + Send,
    on_reply: &mut (impl FnMut(&[u8]) + Send),
    wait: Duration,
    hang_up: impl FnOnce() -> Result<()>,
) -> Talk {
    let (received, stop) = (&AtomicUsize::new(0), &AtomicBool::new(false));
    let mut ends = LineEnds::default();
    let mut early = None;
    thread::scope(|scope| {
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
        while !reading.is_finished() {
            let sent = match input.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => send(port, &mut ends, &buf[..n]),
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(e) => Err(format!("reading the input failed: {e}")),
            };
            if let Err(e) = sent {
                early = Some(e);
                break;
            }
        }
        if early.is_none() && ends.open {
            early = send(port, &mut ends, b"\n").err();
        }
        let deadline = Instant::now() + wait;
        while received.load(Ordering::Acquire) < ends.lines
            && Instant::now() < deadline
            && !reading.is_finished()
        {
            thread::sleep(Duration::from_millis(2));
        }
        stop.store(true, Ordering::Release);
        let hanging_up = hang_up().err().map(|e| format!("hanging up failed: {e:#}"));
        let why = reading
            .join()
            .unwrap_or_else(|_| Some("the reader of the port panicked".to_owned()));
        // The first thing that went wrong is the one to report.
        let early = early.take().or(why).or(hanging_up);
        Talk {
            sent: ends.lines,
            replies: received.load(Ordering::Acquire),
            early,
        }
    })
}

#[cfg(test)]
mod tests {
    use std::net::{Ipv4Addr, TcpListener, TcpStream};

    use super::*;

    #[test]
    fn lines_end_where_the_heads_framer_ends_them() {
        let count = |bytes: &[u8]| {
            let mut ends = LineEnds::default();
            // Split anywhere, it counts the same.
            bytes.chunks(1).for_each(|chunk| ends.feed(chunk));
            (ends.lines, ends.open)
        };
        assert_eq!(count(b""), (0, false));
        assert_eq!(count(b"help\nnod \xff\nstatus\n"), (3, false));
        assert_eq!(count(b"a\r\nb\rc\n\n"), (4, false));
        assert_eq!(count(b"a\nstat"), (1, true));
        assert_eq!(count(b"a\n\x7f"), (1, true));
    }

    /// A conversation with a head on the other end of a socket: one reply
    /// per line (ended by CR, LF or CR LF), the line's bytes echoed after
    /// `got ` (so a 0xff comes back as it went); at `quit`, it closes the
    /// socket without a reply.
    fn talk(input: impl Read) -> (Vec<Vec<u8>>, Talk) {
        let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, 0)).unwrap();
        let mut ours = TcpStream::connect(listener.local_addr().unwrap()).unwrap();
        let (mut theirs, _) = listener.accept().unwrap();
        let head = thread::spawn(move || {
            let (mut buf, mut line, mut after_cr) = ([0_u8; 256], Vec::new(), false);
            while let Ok(n @ 1..) = theirs.read(&mut buf) {
                let mut replies = Vec::new();
                for &b in &buf[..n] {
                    let end = b == b'\r' || (b == b'\n' && !after_cr);
                    after_cr = b == b'\r';
                    if !end {
                        line.extend((b != b'\n').then_some(b));
                    } else if line == b"quit" {
                        let _ = theirs.write_all(&replies);
                        return;
                    } else {
                        replies.extend([b"got ".as_slice(), &line, b"\r\n"].concat());
                        line.clear();
                    }
                }
                if theirs.write_all(&replies).is_err() {
                    return;
                }
            }
        });
        let (reader, hang_up) = (ours.try_clone().unwrap(), ours.try_clone().unwrap());
        let mut got = Vec::new();
        let mut keep = |reply: &[u8]| got.push(reply.to_vec());
        let wait = Duration::from_secs(5);
        let talk = converse(input, &mut ours, reader, &mut keep, wait, || {
            Ok(hang_up.shutdown(std::net::Shutdown::Both)?)
        });
        head.join().unwrap();
        (got, talk)
    }

    #[test]
    fn bytes_go_through_unchanged_and_what_ends_it_early_is_said() {
        // Input that fails after its first line: what was sent is answered.
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
        let (got, said) = talk(b"help\nnod \xff\n\xc3\xa9\rstatus".as_slice());
        // The last line had no line end: it got one.
        let want: [&[u8]; 4] = [b"got help", b"got nod \xff", b"got \xc3\xa9", b"got status"];
        assert_eq!(got, want);
        assert_eq!((said.sent, said.replies, said.problems()), (4, 4, vec![]));
        let (got, said) = talk(b"one\nquit\ntwo\n".as_slice());
        assert_eq!(got, [b"got one"]);
        let problems = said.problems().join("; ");
        assert_eq!(problems, "the port closed; 2 of 3 lines got no reply");
        let (got, said) = talk(Broken(false));
        assert_eq!((said.sent, said.replies, got.len()), (1, 1, 1));
        let early = said.early.unwrap_or_default();
        assert_eq!(early, "reading the input failed: the disk is on fire");
    }
}
