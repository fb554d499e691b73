//! A console port that also speaks Bottango's driver protocol.
//!
//! A [`DualSession`] is a console session (a [`PortSession`]: its
//! framing and replies, the same handler) until a line is a valid
//! Bottango handshake (`hRQ,<code>,h<sum>`): from then on the port's lines
//! are Bottango's ([`crate::bottango::Driver`]), until `STOP` or until the
//! port goes away ([`reset`](DualSession::reset)). Any other line,
//! including a handshake with a wrong hash, is a console line as always,
//! and its reply may wait for the frame task as a [`Session`]'s does
//! ([`waiting`](DualSession::waiting), [`finish`](DualSession::finish)).
//!
//! [`Session`]: super::Session

use super::reply::Reply;
use super::session::{Handler, PortSession};
use crate::bottango::{Curves, Driver};
use crate::text::Out;

/// One port's session, console or Bottango; see the [module docs](self).
#[derive(Debug)]
pub struct DualSession<'a> {
    /// The console session, whose framer and reply buffer the Bottango
    /// lines use too.
    session: PortSession,
    bottango: Driver<'a>,
}

impl<'a> DualSession<'a> {
    /// A console session that becomes a Bottango session on `curves` at a
    /// handshake (`None`: never).
    #[must_use]
    pub const fn new(curves: Option<&'a Curves>) -> Self {
        Self {
            session: PortSession::new(),
            bottango: Driver::new(curves),
        }
    }

    /// Takes one byte; at a line end, the reply (one line for the console,
    /// one or more for Bottango, possibly none for a repeated handshake),
    /// or nothing if a console reply waits for the frame task
    /// ([`waiting`](Self::waiting)). While a reply waits, a byte pushed is
    /// not taken (`None`): finish the reply first.
    pub fn push<H: Handler + ?Sized>(&mut self, byte: u8, handler: &mut H) -> Option<&[u8]> {
        let ended = self.session.step(byte)?;
        if self.bottango.active() {
            let mut out = Out::new(ended.reply);
            self.bottango.line(ended.line, &mut out);
            return Some(out.into_bytes());
        }
        if let Ok(line) = ended.line {
            let mut out = Out::new(&mut *ended.reply);
            let took = self.bottango.handshake(line, &mut out);
            let len = out.len();
            if took {
                return ended.reply.get(..len);
            }
        }
        ended.answer(handler)
    }

    /// The ticket of the queued action whose outcome the last console
    /// line's reply waits for, if it waits.
    #[must_use]
    pub fn waiting(&self) -> Option<u8> {
        self.session.waiting()
    }

    /// Finishes the reply that waits, `write` writing its verdict, and
    /// returns it; `None` if no reply waits.
    pub fn finish(&mut self, write: impl FnOnce(&mut Reply<'_>)) -> Option<&[u8]> {
        self.session.finish(write)
    }

    /// Takes the reply that waits, if one does (see
    /// [`Session::take_later`](super::Session::take_later)).
    pub fn take_later(&mut self) -> Option<super::Later> {
        self.session.take_later()
    }

    /// The reply buffer, for a line of the console's own between replies
    /// (a telemetry line); empty while a reply waits in it.
    pub fn spare(&mut self) -> &mut [u8] {
        self.session.spare()
    }

    /// Whether the port speaks Bottango's protocol.
    #[must_use]
    pub const fn bottango(&self) -> bool {
        self.bottango.active()
    }

    /// Whether a line has begun and not ended.
    #[must_use]
    pub const fn in_progress(&self) -> bool {
        self.session.in_progress()
    }

    /// In a Bottango session, a line that stopped arriving: it is dropped
    /// and answered `TIMEOUT`. `None` otherwise (a console waits for ever).
    pub fn timeout(&mut self) -> Option<&[u8]> {
        if !(self.bottango.active() && self.session.in_progress()) {
            return None;
        }
        let mut out = Out::new(self.session.drop_line());
        self.bottango.timeout(&mut out);
        Some(out.into_bytes())
    }

    /// The port went away (or reconnects): the line in progress is
    /// forgotten and a Bottango session ends.
    pub fn reset(&mut self) {
        self.session.reset();
        self.bottango.end();
    }

    /// The port lost received bytes (see [`Session::lose`](super::Session::lose)).
    pub fn lose(&mut self) {
        self.session.lose();
    }
}
