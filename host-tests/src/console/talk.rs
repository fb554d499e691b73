//! A console service on a simulated head, talked to line by line as a
//! person at a terminal would: one line, its reply, a frame.

use idle_head_core::behaviour::CommandQueue;
use idle_head_core::console::{ConsoleLink, ConsoleService, Session};
use idle_head_core::settings::RamStorage;

use super::head::{SimFrames, service, shared};
use super::{LINE, REPLY};

/// The console service of a simulated head, talked to line by line.
pub struct SimConsole {
    /// The frame task's queue.
    pub queue: &'static CommandQueue,
    /// What the console and the frame task share.
    pub link: &'static ConsoleLink,
    /// The frame side.
    pub frames: SimFrames,
    /// The service.
    pub service: ConsoleService<'static, RamStorage>,
}

impl SimConsole {
    /// On the built-in settings.
    #[must_use]
    pub fn new() -> Self {
        let (queue, link) = shared();
        Self {
            queue,
            link,
            frames: SimFrames::new(),
            service: service(queue, link),
        }
    }

    /// Feeds `text` (lines) to the service, a frame after each line (and
    /// the frames a queued action's reply waits for); the replies.
    ///
    /// # Panics
    /// If a line gets no reply, or one before its line end.
    pub fn say(&mut self, text: &str) -> Vec<String> {
        let mut session = Session::<LINE, REPLY>::new();
        let mut replies = Vec::new();
        for line in text.lines() {
            session.feed(line.as_bytes(), &mut self.service, |_| {
                panic!("reply before the line end")
            });
            let reply = match session.push(b'\n', &mut self.service) {
                Some(reply) => reply.to_vec(),
                None => self
                    .frames
                    .finish(&mut session, self.queue, self.link, 0)
                    .expect("a reply that waits")
                    .to_vec(),
            };
            replies.push(String::from_utf8(reply).unwrap().trim_end().to_owned());
            self.play(1);
        }
        replies
    }

    /// The reply to one line.
    ///
    /// # Panics
    /// As [`say`](Self::say).
    pub fn ask(&mut self, line: &str) -> String {
        self.say(line).remove(0)
    }

    /// Plays `n` frames.
    pub fn play(&mut self, n: usize) {
        for _ in 0..n {
            self.frames.frame(self.queue, self.link);
        }
    }
}

impl Default for SimConsole {
    fn default() -> Self {
        Self::new()
    }
}
