//! The serial console: where bytes become commands and replies.
//!
//! - [`Framer`]: bytes → lines (line ends, backspace, overlong lines,
//!   control bytes, UTF-8).
//! - [`parse`]: one line → a [`Command`](crate::command::Command).
//! - [`Session`]: both, a [`Handler`] that carries the commands out, and
//!   exactly one [`Reply`] line per input line (`ok …` or
//!   `err <code> <reason>`, codes in [`ErrorCode`]).
//! - [`ConsoleService`]: the handler that carries every command out,
//!   through the frame task's queue and the [`ConsoleLink`] it shares
//!   with the frame task. The reply to a queued action waits until the
//!   frame task has taken or refused it ([`Reply::defer`],
//!   [`Session::finish`], [`outcome_reply`]).
//! - [`Outbox`]: a port's replies in line order while some wait for the
//!   frame task, so that the port reads on meanwhile.
//! - [`telemetry_line`]: the lines `watch` streams.
//! - [`DualSession`]: a port's session that turns into a Bottango driver
//!   at a Bottango handshake ([`crate::bottango`]).
//!
//! Nothing here allocates or panics. See `docs/user/protocol.md` for the
//! protocol as a user sees it.

mod framer;
mod link;
mod outbox;
mod outcome;
mod parse;
mod parts;
mod port;
mod reply;
mod service;
mod session;
mod shared;
mod telemetry;

pub use framer::{Framer, LineError};
pub use link::{ConsoleLink, HeadMode, HeadStatus, IdleView, OUTCOMES, Outcome, PORTS};
pub use outbox::{HELD, Outbox, WAITING};
pub use outcome::{outcome_reply, unanswered};
pub use parse::{ActionLine, KEYWORDS, ParseError, ParseErrorKind, Span, parse};
pub use parts::BoardParts;
pub use port::DualSession;
pub use reply::{ErrorCode, Reply};
pub use service::{ConsoleService, HELP, VERSION};
pub use session::{
    EnvelopeError, Handler, InputError, Later, MIN_REPLY, PORT_LINE, PORT_REPLY, PortSession,
    Response, Session, checksum, respond,
};
pub use shared::{Shared, SharedService};
pub use telemetry::{MAX_WATCH_HZ, TELEMETRY_LINE, telemetry_line};

/// How a board's USB serial port (CDC-ACM) introduces itself, so that a
/// host finds the head among other serial devices.
pub mod usb_identity {
    /// The shared V-USB vendor ID (Van Ooijen Technische Informatica).
    pub const VID: u16 = 0x16c0;
    /// Its product ID for CDC-ACM serial devices of hobby projects, shared
    /// by many: a host tells a head from the others by [`PRODUCT`].
    pub const PID: u16 = 0x27dd;
    /// Manufacturer string descriptor.
    pub const MANUFACTURER: &str = "idle-head";
    /// Product string descriptor: what the host tools look for.
    pub const PRODUCT: &str = "idle-head console";
}
