//! Bottango's driver protocol: a console port becomes a Bottango driver
//! for the head's three axes.
//!
//! A port's session switches to this protocol at Bottango's handshake and
//! back at `STOP` (or when the host goes away). Curves go to the frame task
//! through [`Curves`], sampled on its clock; the show layer blends them over
//! the mixer's offsets. [`VERSION`] is the protocol version answered.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Bottango”).

pub mod curve;
pub mod line;
pub mod queue;
mod session;

pub use curve::{Curve, INSTANT_HOLD_MS};
pub use line::{Command, LineError, checked, hash, parse};
pub use queue::{Curves, DEPTH, MotorError, Op, Sample};
pub use session::{Driver, MAX_LINE, TIMEOUT_MS, VERSION};
