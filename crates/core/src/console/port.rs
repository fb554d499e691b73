//! A console port that also speaks Bottango's driver protocol.
//!
//! A [`DualSession`] is a console session ([`Session`](super::Session)'s
//! framing and replies, the same handler) until a line is a valid
//! Bottango handshake (`hRQ,<code>,h<sum>`): from then on the port's lines
//! are Bottango's ([`crate::bottango::Driver`]), until `STOP` or until the
//! port goes away ([`reset`](DualSession::reset)). Any other line,
//! including a handshake with a wrong hash, is a console line as always.

use super::framer::Framer;
use super::session::{Handler, respond};
use crate::bottango::{Curves, Driver, Out};

/// Bytes of a line, as the console's protocol promises (and the Bottango
/// modules answer reports).
pub const LINE: usize = crate::bottango::MAX_LINE;
/// Bytes of a reply line.
pub const REPLY: usize = 160;

/// One port's session, console or Bottango; see the [module docs](self).
#[derive(Debug)]
pub struct DualSession<'a> {
    framer: Framer<LINE>,
    reply: [u8; REPLY],
    bottango: Driver<'a>,
}

impl<'a> DualSession<'a> {
    /// A console session that becomes a Bottango session on `curves` at a
    /// handshake (`None`: never).
    #[must_use]
    pub const fn new(curves: Option<&'a Curves>) -> Self {
        Self {
            framer: Framer::new(),
            reply: [0; REPLY],
            bottango: Driver::new(curves),
        }
    }

    /// Takes one byte; at a line end, the reply (one line for the console,
    /// one or more for Bottango, possibly none for a repeated handshake).
    pub fn push<H: Handler + ?Sized>(&mut self, byte: u8, handler: &mut H) -> Option<&[u8]> {
        let outcome = self.framer.push(byte)?;
        if self.bottango.active() {
            let mut out = Out::new(&mut self.reply);
            self.bottango.line(outcome, &mut out);
            return Some(out.into_bytes());
        }
        if let Ok(line) = outcome {
            let mut out = Out::new(&mut self.reply);
            let took = self.bottango.handshake(line, &mut out);
            let len = out.len();
            if took {
                return self.reply.get(..len);
            }
        }
        Some(respond(outcome, handler, &mut self.reply))
    }

    /// Whether the port speaks Bottango's protocol.
    #[must_use]
    pub const fn bottango(&self) -> bool {
        self.bottango.active()
    }

    /// Whether a line has begun and not ended.
    #[must_use]
    pub const fn in_progress(&self) -> bool {
        self.framer.in_progress()
    }

    /// In a Bottango session, a line that stopped arriving: it is dropped
    /// and answered `TIMEOUT`. `None` otherwise (a console waits for ever).
    pub fn timeout(&mut self) -> Option<&[u8]> {
        if !(self.bottango.active() && self.framer.in_progress()) {
            return None;
        }
        self.framer.reset();
        let mut out = Out::new(&mut self.reply);
        self.bottango.timeout(&mut out);
        Some(out.into_bytes())
    }

    /// The port went away (or reconnects): the line in progress is
    /// forgotten and a Bottango session ends.
    pub fn reset(&mut self) {
        self.framer.reset();
        self.bottango.end();
    }

    /// The port lost received bytes (see [`Framer::lose`]).
    pub fn lose(&mut self) {
        self.framer.lose();
    }
}
