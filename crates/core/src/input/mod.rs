//! Trigger inputs: what a button or a presence sensor means for the head.
//!
//! A board reads its inputs' levels (the firmware layer's `InputSource`);
//! everything that decides what a level means lives here, hardware-free and
//! tested on the host:
//!
//! - [`InputRole`]: what an input is: off, a button with an action, or a
//!   presence sensor with an optional direction ([`role`]);
//! - [`Debouncer`]: a level becomes an edge by the role's rule
//!   ([`Debounce`]): a button's press at once, a presence sensor's level
//!   once it has held ([`debounce`]);
//! - [`Inputs`]: every input's debouncer, what its edges do (a button's
//!   action, a presence sensor's wake and glance), and the rest timer: the
//!   head rests when presence inputs are configured and none has been
//!   active for [`RestAfter`] ([`inputs`]).
//!
//! What comes out are the same [`Action`](crate::command::Action)s the
//! console sends, for the frame task's command queue.
//!
//! # Times
//!
//! | what | time | why |
//! |---|---|---|
//! | button debounce | [`BUTTON_DEBOUNCE`] = 5 ms | a switch's contacts bounce for a few ms after the first touch; the press counts at that touch and the input is not looked at for 5 ms after it (the usual figure keyboard firmware uses) |
//! | button hold-off | [`BUTTON_HOLD_OFF`] = 200 ms | presses closer together than that are one press (a switch that bounces longer than the debounce, a double tap) |
//! | presence debounce | [`PRESENCE_DEBOUNCE`] = 50 ms | a PIR module's output is clean logic held for seconds (an HC-SR501 for its hold time of 3 s up, an AM312 for about 2 s): 50 ms rejects what a long cable picks up, and costs nothing a visitor would notice |
//! | glance hold-off | [`GLANCE_HOLD_OFF`] = 10 s | a PIR module re-triggers every few seconds while someone moves in front of it (and an HC-SR501 is blind for about 3 s after each pulse): the head glances once, not at every pulse |
//!
//! # Chatter, stuck inputs, two sensors at once
//!
//! - A presence level that changes faster than its debounce time never
//!   holds long enough: chatter is no edge at all. A button's bounces come
//!   within the 5 ms after its edge, when it is not looked at.
//! - A button held down (or stuck low) acts once; it acts again only after
//!   it has been released.
//! - A presence input held high (someone standing there, or a sensor stuck
//!   high) is presence for as long as it lasts: the head stays awake. A
//!   sensor stuck low (or unplugged: the pull-down holds it there) is
//!   nobody: the head rests after the timeout and only a button, a console
//!   `wake` or another sensor wakes it. `status` shows each input's level.
//! - An input already active when it is configured (at power-up, or when
//!   its role changes) counts as active, but is no edge: a button held at
//!   power-up does nothing until pressed again.
//! - Two presence inputs that rise at once (in one update) wake the head
//!   once; the glance goes to the lower-numbered one. Either of them active
//!   keeps the head awake.

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
