//! A port's replies in line order while some wait for the frame task.
//!
//! The reply to a queued action waits for its outcome, up to a few frames.
//! Its port reads on meanwhile: the lines after it are answered as they
//! come, and their replies are held here, behind the one that waits, until
//! it is written. Every line still gets exactly one reply, in the order of
//! the lines, and a burst of commands is queued for the frame task within
//! the same frame instead of one command a frame.
//!
//! ```text
//! line:    look …   status   nod      watch 5
//! reply:   (waits)  (held)   (waits)  (held)
//! frame k takes look and nod: look's reply, status's, nod's, watch's go out
//! ```

use crate::behaviour::{Applied, BehaviourError};

use super::link::Outcome;
use super::outcome::{outcome_reply, unanswered};
use super::session::{Later, PORT_REPLY};

/// Replies that may wait at once on a port: as many actions as the command
/// queue holds.
pub const WAITING: usize = crate::behaviour::queue::CAPACITY;

/// Bytes of replies held behind the ones that wait.
pub const HELD: usize = 512;

/// What became of a reply that waits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Verdict {
    /// No outcome yet.
    Open,
    /// The frame task took or refused the action.
    Taken(Result<Applied, BehaviourError>),
    /// No frame took it within this many ms.
    Unanswered(u32),
}

/// A reply that waits, and the held bytes that follow it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Waiting {
    later: Later,
    /// When it is given up on (the caller's clock).
    due: u64,
    verdict: Verdict,
    /// Held bytes between this reply and the next one that waits.
    after: usize,
}

/// A port's replies in line order; see the [module docs](self).
#[derive(Clone, Debug)]
pub struct Outbox {
    waiting: [Option<Waiting>; WAITING],
    /// Index of the oldest in `waiting`, and how many there are.
    head: usize,
    len: usize,
    /// Replies that came after the oldest reply that waits, in order.
    held: [u8; HELD],
    held_len: usize,
    /// Held bytes at the front that no reply waits before any more: the
    /// next to write.
    free: usize,
}

impl Default for Outbox {
    fn default() -> Self {
        Self::new()
    }
}

impl Outbox {
    /// Nothing waits, nothing held.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            waiting: [None; WAITING],
            head: 0,
            len: 0,
            held: [0; HELD],
            held_len: 0,
            free: 0,
        }
    }

    /// Whether the next line's reply has room: a slot to wait in and room
    /// for a whole reply to be held. The port stops reading until it has.
    #[must_use]
    pub const fn has_room(&self) -> bool {
        self.len < WAITING && HELD - self.held_len >= PORT_REPLY
    }

    /// Whether a reply waits (or has bytes held behind it).
    #[must_use]
    pub const fn is_busy(&self) -> bool {
        self.len > 0 || self.held_len > 0
    }

    /// A reply line: `Some` (the line) to write now if nothing waits
    /// before it, else held (`None`). A line that finds no room is cut to
    /// what fits (callers check [`has_room`](Self::has_room) first).
    pub fn reply<'r>(&mut self, line: &'r [u8]) -> Option<&'r [u8]> {
        if !self.is_busy() {
            return Some(line);
        }
        let room = HELD - self.held_len;
        let take = line.len().min(room);
        let (Some(to), Some(from)) = (
            self.held.get_mut(self.held_len..self.held_len + take),
            line.get(..take),
        ) else {
            return None;
        };
        to.copy_from_slice(from);
        self.held_len += take;
        match self.newest() {
            Some(newest) => newest.after += take,
            None => self.free += take,
        }
        None
    }

    /// A reply that waits for the outcome of `later`'s action until `due`
    /// (on the caller's clock).
    ///
    /// # Errors
    /// `later` back if [`WAITING`] replies wait already.
    pub fn wait(&mut self, later: Later, due: u64) -> Result<(), Later> {
        if self.len >= WAITING {
            return Err(later);
        }
        let slot = self.waiting.get_mut((self.head + self.len) % WAITING);
        let Some(slot) = slot else {
            return Err(later);
        };
        *slot = Some(Waiting {
            later,
            due,
            verdict: Verdict::Open,
            after: 0,
        });
        self.len += 1;
        Ok(())
    }

    /// The outcome of an action: the reply waiting for its ticket has its
    /// verdict. An outcome no reply waits for (one given up on) is dropped.
    pub fn resolve(&mut self, outcome: &Outcome) {
        for i in 0..self.len {
            if let Some(Some(w)) = self.waiting.get_mut((self.head + i) % WAITING)
                && w.verdict == Verdict::Open
                && w.later.ticket() == outcome.ticket
            {
                w.verdict = Verdict::Taken(outcome.result);
                return;
            }
        }
    }

    /// Replies still open at `now` past their due time are given up on:
    /// answered as [`unanswered`] after `waited_ms`.
    pub fn expire(&mut self, now: u64, waited_ms: u32) {
        for i in 0..self.len {
            if let Some(Some(w)) = self.waiting.get_mut((self.head + i) % WAITING)
                && w.verdict == Verdict::Open
                && now >= w.due
            {
                w.verdict = Verdict::Unanswered(waited_ms);
            }
        }
    }

    /// When the oldest open reply is given up on, if one is open.
    #[must_use]
    pub fn due(&self) -> Option<u64> {
        (0..self.len)
            .filter_map(|i| {
                self.waiting
                    .get((self.head + i) % WAITING)
                    .copied()
                    .flatten()
            })
            .filter(|w| w.verdict == Verdict::Open)
            .map(|w| w.due)
            .min()
    }

    /// Copies the next bytes ready to go out (the replies whose turn has
    /// come, in order) into `out`, at most its length, and returns how
    /// many; 0 when the next reply still waits or nothing is left. `out`
    /// should hold a whole reply ([`PORT_REPLY`]): one that does not fit is
    /// cut.
    pub fn take_ready(&mut self, out: &mut [u8]) -> usize {
        if self.free > 0 {
            let n = self.free.min(out.len());
            if let (Some(to), Some(from)) = (out.get_mut(..n), self.held.get(..n)) {
                to.copy_from_slice(from);
            }
            self.held.copy_within(n..self.held_len, 0);
            self.held_len -= n;
            self.free -= n;
            return n;
        }
        let Some(Some(oldest)) = self.waiting.get(self.head).copied() else {
            return 0;
        };
        let reply = match oldest.verdict {
            Verdict::Open => return 0,
            Verdict::Taken(result) => oldest
                .later
                .finish(out, |reply| outcome_reply(reply, &result)),
            Verdict::Unanswered(ms) => oldest.later.finish(out, |reply| unanswered(reply, ms)),
        };
        let n = reply.len();
        if let Some(slot) = self.waiting.get_mut(self.head) {
            *slot = None;
        }
        self.head = (self.head + 1) % WAITING;
        self.len -= 1;
        self.free = oldest.after;
        n
    }

    /// Forgets every reply, waiting or held (the port's host went away).
    pub fn clear(&mut self) {
        *self = Self::new();
    }

    /// The newest reply that waits.
    fn newest(&mut self) -> Option<&mut Waiting> {
        let last = (self.head + self.len.checked_sub(1)?) % WAITING;
        self.waiting.get_mut(last)?.as_mut()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::behaviour::CommandQueue;
    use crate::command::Action;
    use crate::console::{ConsoleLink, Session};

    /// Everything ready, as text.
    fn drain(outbox: &mut Outbox) -> String {
        let mut text = String::new();
        let mut buf = [0; PORT_REPLY];
        loop {
            let n = outbox.take_ready(&mut buf);
            if n == 0 {
                return text;
            }
            text.push_str(core::str::from_utf8(&buf[..n]).unwrap());
        }
    }

    /// A deferred reply for `ticket`, as the session makes one.
    fn later(ticket: u8, line: &[u8]) -> Later {
        let mut session = Session::<96, 160>::new();
        let mut handler = |_: crate::command::Command, reply: &mut super::super::Reply<'_>| {
            reply.defer(ticket);
        };
        for &b in line {
            assert_eq!(session.push(b, &mut handler), None);
        }
        session.take_later().unwrap()
    }

    /// A machine-mode line: `body`, its checksum and the line end.
    fn machine(body: &str) -> Vec<u8> {
        let crc = crate::console::checksum(body.as_bytes());
        format!("{body} *{crc:02x}\n").into_bytes()
    }

    fn taken(ticket: u8) -> Outcome {
        Outcome {
            ticket,
            result: Ok(Applied::Idle(crate::command::Percent::FULL)),
        }
    }

    #[test]
    fn replies_go_out_in_line_order_behind_the_one_that_waits() {
        let mut outbox = Outbox::new();
        assert_eq!(outbox.reply(b"ok a\r\n"), Some(&b"ok a\r\n"[..]));
        outbox.wait(later(1, b"idle on\n"), 100).unwrap();
        assert_eq!(outbox.reply(b"ok b\r\n"), None);
        outbox.wait(later(2, &machine("#7 idle on")), 100).unwrap();
        assert_eq!(outbox.reply(b"ok c\r\n"), None);
        assert_eq!(drain(&mut outbox), "");
        // The second's outcome first: nothing goes out before the first's.
        outbox.resolve(&taken(2));
        assert_eq!(drain(&mut outbox), "");
        outbox.resolve(&taken(1));
        let text = drain(&mut outbox);
        assert!(text.starts_with("ok idle=100\r\nok b\r\n"), "{text}");
        assert!(text.contains("ok c\r\n"));
        assert!(!outbox.is_busy());
        assert_eq!(outbox.reply(b"ok d\r\n"), Some(&b"ok d\r\n"[..]));
    }

    #[test]
    fn a_machine_mode_reply_keeps_its_sequence_number() {
        let mut outbox = Outbox::new();
        outbox.wait(later(9, &machine("#41 idle on")), 0).unwrap();
        outbox.resolve(&taken(9));
        let text = drain(&mut outbox);
        assert!(text.starts_with("#41 ok idle=100 *"), "{text}");
    }

    #[test]
    fn a_reply_past_its_time_is_unanswered_and_its_late_outcome_dropped() {
        let mut outbox = Outbox::new();
        outbox.wait(later(3, b"nod\n"), 50).unwrap();
        outbox.reply(b"ok x\r\n");
        assert_eq!(outbox.due(), Some(50));
        outbox.expire(49, 100);
        assert_eq!(drain(&mut outbox), "");
        outbox.expire(50, 100);
        assert_eq!(outbox.due(), None);
        let text = drain(&mut outbox);
        assert!(
            text.starts_with("err state no frame took the command within 100 ms"),
            "{text}"
        );
        assert!(text.ends_with("ok x\r\n"));
        outbox.resolve(&taken(3));
        assert_eq!(drain(&mut outbox), "");
    }

    #[test]
    fn room_runs_out_with_every_slot_waiting_or_the_held_bytes_full() {
        let mut outbox = Outbox::new();
        for ticket in 0..WAITING as u8 {
            assert!(outbox.has_room());
            outbox.wait(later(ticket, b"nod\n"), 0).unwrap();
        }
        assert!(!outbox.has_room());
        let extra = later(99, b"nod\n");
        assert_eq!(outbox.wait(extra, 0), Err(extra));
        outbox.clear();
        outbox.wait(later(1, b"nod\n"), 0).unwrap();
        while outbox.has_room() {
            assert_eq!(outbox.reply(&[b'x'; 40]), None);
        }
        assert!(HELD - outbox.held_len < PORT_REPLY);
    }

    #[test]
    fn the_frame_task_answers_through_the_link_in_order() {
        static QUEUE: CommandQueue = CommandQueue::new();
        static LINK: ConsoleLink = ConsoleLink::new();
        let params = crate::settings::Settings::DEFAULT
            .validate(&crate::driver::DriverConfig::DEFAULT)
            .unwrap()
            .behaviour;
        let mut outbox = Outbox::new();
        for ticket in [5, 6] {
            QUEUE
                .try_submit_from(
                    Action::Idle(true),
                    crate::behaviour::Asker { port: 1, ticket },
                )
                .unwrap();
            outbox.wait(later(ticket, b"idle on\n"), 0).unwrap();
        }
        // (the frame task takes both in one frame and answers each)
        while let Some((action, asker)) = QUEUE.take_asked() {
            LINK.answer(asker.unwrap(), params.check(&action));
        }
        while let Some(outcome) = LINK.take_outcome(1) {
            outbox.resolve(&outcome);
        }
        assert_eq!(drain(&mut outbox).matches("ok idle=").count(), 2);
    }
}
