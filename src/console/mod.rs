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
//!   with the frame task.
//!
//! Nothing here allocates or panics. See `docs/protocol.md` for the
//! protocol as a user sees it.

mod framer;
mod link;
mod parse;
mod reply;
mod service;
mod session;

pub use framer::{Framer, LineError};
pub use link::{ConsoleLink, HeadMode, HeadStatus};
pub use parse::{ParseError, ParseErrorKind, Span, parse};
pub use reply::{ErrorCode, Reply};
pub use service::{ConsoleService, VERSION};
pub use session::{EnvelopeError, Handler, InputError, MIN_REPLY, Session, checksum, respond};

/// The reply to `help`: the command words, one line.
pub const HELP: &str =
    "commands: help status stop nod shake tilt look center idle seed servo save load defaults";
