//! Trigger inputs: what a button or a presence sensor means for the head.
//!
//! A board reads its inputs' levels (the firmware layer's `InputSource`);
//! what a level means lives here: [`InputRole`] (off, a button with an
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
mod inputs;
mod role;
mod settings;

pub use debounce::{Debounce, Debouncer};
pub use inputs::{InputStatus, Inputs, Micros, OUTBOX, RADAR_HOLD_MS, RADAR_POLL_MS};
pub use role::{InputRole, Pull};
pub use settings::{InputSettings, MAX_REST_AFTER, RestAfter};

use crate::units::Millis;

/// How many trigger inputs a head has (GP2 to GP5 on the Pico).
pub const INPUTS: usize = 4;

/// The first input's number in the console's words (`input 2`): the Pico's
/// GPIO numbers.
pub const FIRST_INPUT: u8 = 2;

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
