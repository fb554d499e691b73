//! A motion command as a line: the parser's inverse, for what the console
//! shows (a button's action in `input <n>`).
//!
//! The line is the canonical spelling: lower case, one space between words,
//! the options given in the order `cycles=`, `intensity=`, `hold=`; the
//! parser reads it back as the same action (the host tests check every
//! kind). A wake with a direction comes from a presence input, never from a
//! line: it is written `wake` and its direction is left out.

use crate::command::{Action, Hold};
use crate::text::{Describe, Text};

/// `action` as the console line that asks for it.
///
/// ```
/// use idle_head_core::command::Command;
/// use idle_head_core::console::{ActionLine, parse};
///
/// let Ok(Command::Act(nod)) = parse(b"NOD  6000 intensity=70") else { panic!() };
/// assert_eq!(ActionLine(&nod).to_string(), "nod 6000 intensity=70");
/// ```
#[derive(Clone, Copy, Debug)]
pub struct ActionLine<'a>(pub &'a Action);

impl Describe for ActionLine<'_> {
    #[inline(never)]
    fn describe(&self, out: &mut dyn Text) {
        match *self.0 {
            Action::Gesture(g) => {
                out.str(g.kind.name());
                // The duration is positional after the amplitude: a line has
                // one only with an amplitude (nor does a stored action).
                if let Some(a) = g.amplitude {
                    out.str(" ").i64(a.millidegrees().into());
                    if let Some(d) = g.duration {
                        out.str(" ").u64(d.0.into());
                    }
                }
                if let Some(c) = g.cycles {
                    out.str(" cycles=").u64(c.into());
                }
                if let Some(i) = g.intensity {
                    out.str(" intensity=").u64(i.get().into());
                }
            }
            Action::Look(l) => {
                out.str("look ")
                    .i64(l.pitch.millidegrees().into())
                    .str(" ")
                    .i64(l.yaw.millidegrees().into());
                if let Some(d) = l.duration {
                    out.str(" ").u64(d.0.into());
                }
                match l.hold {
                    Some(Hold::Stay) => {
                        out.str(" hold=stay");
                    }
                    Some(Hold::Return(ms)) => {
                        out.str(" hold=").u64(ms.0.into());
                    }
                    None => {}
                }
            }
            Action::Center { duration } => {
                out.str("center");
                if let Some(d) = duration {
                    out.str(" ").u64(d.0.into());
                }
            }
            Action::Idle(on) => {
                out.str(if on { "idle on" } else { "idle off" });
            }
            Action::IdleAmp(p) => {
                out.str("idle amp ").u64(p.get().into());
            }
            Action::Stop => {
                out.str("stop");
            }
            Action::Rest => {
                out.str("rest");
            }
            Action::Wake { .. } => {
                out.str("wake");
            }
        }
    }
}

crate::text::display_from_describe!(ActionLine<'_>);
