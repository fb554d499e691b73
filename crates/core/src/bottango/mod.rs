//! Bottango's driver protocol: a console port becomes a Bottango driver
//! for the head's three axes.
//!
//! Bottango (an animation app for robots) drives boards through a driver
//! over a serial line: ASCII lines, a hash on each, `OK` after each command
//! ([`line`], [`Driver`]). A console port that receives a valid handshake
//! (`hRQ`) speaks this protocol until `STOP` or until the port goes away
//! ([`crate::console::DualSession`]); any other line stays in the console.
//!
//! # Version and what is implemented
//!
//! The handshake reports driver version [`VERSION`] (0.8.0c1): the
//! protocol of Bottango's Arduino driver of that version, as far as a head
//! of three axes needs it:
//!
//! - framing and the `h<sum>` hash (`OK`, `HASH_FAIL`, and `TIMEOUT` for a
//!   line that stops arriving for [`TIMEOUT_MS`]);
//! - `hRQ` (handshake), `hMOD` and `OK` (the modules answer: live commands
//!   only, lines up to [`MAX_LINE`] bytes, [`DEPTH`] curves per motor, no
//!   synchronised commands, 32-bit signals), `tSYN`, `STOP`;
//! - custom motors: `rMTR` registers one of the identifiers `pitch`,
//!   `roll`, `yaw` (exactly, lower case), `upE` changes its bounds, `xUE`
//!   and `xE` deregister; the signal is the axis angle in millidegrees
//!   (set the motor's minimum and maximum signal to the axis' limits);
//! - `sC` (a cubic Bézier of movement over time, movement 0–8192 mapped
//!   to the motor's signal range), `sCI` (an instant target, held for
//!   [`INSTANT_HOLD_MS`]), `xC`, `xUC`.
//!
//! Left out (each answered `errUnsupported: <name>` and `OK`, so the app
//! goes on): servos and steppers on the board's pins (`rSVPin`,
//! `rSVI2C`, `rSTPin`, `rSTDir`; the head's servos are its custom motors),
//! custom events and their curves (`rECC`, `rECOnOff`, `rECTrig`,
//! `rECColor`, `sCO`, `sCT`, `sCC`, `sCCI`), stepper sync (`sycM`),
//! synchronised commands (`sSY`), relays, configuration (`sCfg`), audio,
//! exported animations, and the `BOOT` line at power-on (the port is a
//! console first). A motor's speed limit (`rMTR`'s signal speed) and start
//! signal are not used: the head's own speed and acceleration limits apply
//! to every layer, and it starts where it is.
//!
//! # Time
//!
//! Curves are timed on the frame task's clock (frame × frame period):
//! `tSYN` marks the clock's value at the last frame, and each `sC` starts
//! its curve that many milliseconds later. A curve therefore starts up to
//! one frame (20 ms) after Bottango meant it to, all of them alike.

pub mod curve;
pub mod line;
pub mod queue;
mod session;

pub use curve::{Curve, INSTANT_HOLD_MS};
pub use line::{Command, LineError, checked, hash, parse};
pub use queue::{Curves, DEPTH, MotorError, Op, Sample};
pub use session::{Driver, MAX_LINE, TIMEOUT_MS, VERSION};
