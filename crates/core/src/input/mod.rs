//! Trigger inputs: what a button or a presence sensor means for the head.
//!
//! A board reads its inputs' levels (the firmware layer's `InputSource`)
//! and names them ([`InputIds`]: how many, and each one's number); what a
//! level means lives here: [`InputRole`] (off, a button with an
//! action, a presence sensor), [`Debouncer`] (a button's press at once, a
//! presence level once it has held, [`Debounce`]) and [`Inputs`], which
//! turns edges into the same [`Action`](crate::command::Action)s the console
//! sends and rests the head after [`RestAfter`] without presence. Chatter
//! is no edge; a held button acts once; an input active when configured is
//! no edge.
//!
//! Why it is built so: the book's notes on the code
//! (`docs/design/code.md`, “Trigger inputs”).

mod debounce;
mod ids;
mod inputs;
mod role;
mod settings;

pub use debounce::{Debounce, Debouncer};
pub use ids::{IdsError, InputIds};
pub use inputs::{InputStatus, Inputs, Micros, OUTBOX, RADAR_HOLD_MS, RADAR_POLL_MS};
pub use role::{InputRole, Pull};
pub use settings::{InputSettings, MAX_REST_AFTER, RestAfter};

use crate::units::Millis;

/// How many inputs the settings keep a role for: the most a board can
/// have. The board says how many it has and their numbers ([`InputIds`]);
/// its input in slot `i` takes role `i` (the settings record keeps all
/// four, so a record saved on one board loads on another).
pub const SLOTS: usize = 4;

/// A button's level must hold this long to count.
pub const BUTTON_DEBOUNCE: Millis = Millis(5);

/// Presses closer together than this after an accepted one are ignored.
pub const BUTTON_HOLD_OFF: Millis = Millis(200);

/// A presence sensor's level must hold this long to count.
pub const PRESENCE_DEBOUNCE: Millis = Millis(50);

/// At most one glance in this time.
pub const GLANCE_HOLD_OFF: Millis = Millis(10_000);

#[cfg(test)]
mod tests;
