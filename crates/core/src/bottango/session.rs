//! The driver side of one port's Bottango session.

use super::curve::Curve;
use super::line::{self, Command, Motor};
use super::queue::{Curves, DEPTH, MotorError, Op};
use crate::console::LineError as FramerError;
use crate::text::Out;

/// The driver version the handshake reports: the protocol of Bottango's
/// Arduino driver of that version, as far as this head implements it
/// (see the [module docs](super)).
pub const VERSION: &str = "0.8.0c1";

/// The longest line the port takes (the console's), as the modules answer
/// reports it to the app.
pub const MAX_LINE: usize = crate::console::PORT_LINE;

const OK: &[u8] = b"OK\n";

/// One port's Bottango session: whether the port speaks the protocol, and
/// what it needs to carry its commands out.
#[derive(Debug)]
pub struct Driver<'a> {
    curves: Option<&'a Curves>,
    /// The port speaks Bottango's protocol.
    on: bool,
    /// The next part of the modules answer (0: none pending).
    modules: u8,
    /// The head's clock at the last time sync, ms: `sC` times its curves
    /// from there.
    sync: u32,
}

impl<'a> Driver<'a> {
    /// A port that speaks the console's protocol until a handshake, and
    /// then Bottango's on `curves` (`None`: never).
    #[must_use]
    pub const fn new(curves: Option<&'a Curves>) -> Self {
        Self {
            curves,
            on: false,
            modules: 0,
            sync: 0,
        }
    }

    /// Whether the port speaks Bottango's protocol.
    #[must_use]
    pub const fn active(&self) -> bool {
        self.on
    }

    /// A console line: if it is a valid Bottango handshake, the port
    /// switches to Bottango's protocol (every motor of an earlier session
    /// deregistered) and the handshake's answer is written to `out`.
    pub fn handshake(&mut self, line: &[u8], out: &mut Out<'_>) -> bool {
        // Every console line comes here: most are no handshake by their
        // first bytes, and need no hash summed.
        if !line::may_be_handshake(line) {
            return false;
        }
        let (Some(curves), Ok(Command::Handshake(code))) = (self.curves, line::parse(line)) else {
            return false;
        };
        curves.set_active(false);
        curves.set_active(true);
        self.on = true;
        self.modules = 0;
        self.sync = curves.clock();
        out.put(b"btngoHSK,")
            .put(VERSION.as_bytes())
            .put(b",")
            .put(code)
            .put(b"\n")
            .put(OK);
        true
    }

    /// The port went away: the session ends (its motors deregistered: the
    /// head hands back to its own motion).
    pub fn end(&mut self) {
        if self.on
            && let Some(curves) = self.curves
        {
            curves.set_active(false);
        }
        self.on = false;
        self.modules = 0;
    }

    /// A line in progress stopped arriving (for [`TIMEOUT_MS`]): the
    /// answer, `TIMEOUT`.
    pub fn timeout(&mut self, out: &mut Out<'_>) {
        out.put(b"TIMEOUT\n");
    }

    /// One line of the session (the framer's outcome); the answer goes to
    /// `out`. After `STOP` the port speaks the console's protocol again.
    pub fn line(&mut self, line: Result<&[u8], FramerError>, out: &mut Out<'_>) {
        let Some(curves) = self.curves else {
            return;
        };
        let line = match line {
            Ok(line) => line,
            Err(FramerError::TooLong { len, .. }) => {
                out.put(b"\nerrCmdTooLong: ");
                out.text().u64(len as u64);
                out.put(b"\n").put(OK);
                return;
            }
            // Bytes lost or damaged on the way: the hash would not match.
            Err(_) => {
                out.put(b"HASH_FAIL\n");
                return;
            }
        };
        let command = match line::parse(line) {
            Ok(command) => command,
            Err(line::LineError::Hash) => {
                out.put(b"HASH_FAIL\n");
                return;
            }
            Err(line::LineError::Syntax(what)) => {
                out.put(b"\nerrBadParameters: expected ")
                    .put(what.as_bytes())
                    .put(b"\n")
                    .put(OK);
                return;
            }
        };
        match command {
            // A repeated handshake is ignored, as Bottango's own driver
            // ignores one: no answer at all.
            Command::Handshake(_) => return,
            Command::Modules => {
                out.put(OK);
                self.modules = 1;
                self.module(out);
                return;
            }
            Command::Continue => {
                out.put(OK);
                self.module(out);
                return;
            }
            // The app's clock is not needed: `sC` times its curves from
            // the last sync, which is now.
            Command::TimeSync(_) => self.sync = curves.clock(),
            Command::Stop => {
                self.end();
                out.put(OK);
                return;
            }
            Command::DeregisterAll => curves.deregister_all(),
            Command::ClearAll => curves.clear_all(),
            Command::Deregister(motor) => on_motor(curves, motor, Op::Deregister, out),
            Command::Clear(motor) => on_motor(curves, motor, Op::Clear, out),
            Command::Register(motor, b) => {
                let op = Op::Register {
                    min: b.min,
                    max: b.max,
                };
                on_motor(curves, motor, op, out);
            }
            Command::Bounds(motor, b) => {
                let op = Op::Bounds {
                    min: b.min,
                    max: b.max,
                };
                on_motor(curves, motor, op, out);
            }
            Command::Curve(motor, args) => {
                // A start before the sync wraps back: the curve is late.
                let start = self.sync.wrapping_add(args.start as u32);
                on_motor(curves, motor, Op::Push(Curve::new(start, &args)), out);
            }
            Command::Instant(motor, movement) => {
                let curve = Curve::hold(curves.clock(), movement);
                on_motor(curves, motor, Op::Push(curve), out);
            }
            Command::Other(name) => {
                out.put(b"\nerrUnsupported: ").put(name).put(b"\n");
            }
        }
        out.put(OK);
    }

    /// The next part of the modules answer, if one is pending.
    fn module(&mut self, out: &mut Out<'_>) {
        match self.modules {
            // Live commands only: no exported animations on the board.
            1 => out.put(b"MOD,CMD_SRC,0\n"),
            // Longest line, curves kept per motor, no synchronised
            // commands, 32-bit signals.
            2 => {
                out.text()
                    .str("MOD,CMD_CFG,")
                    .u64(MAX_LINE as u64)
                    .str(",")
                    .u64(DEPTH as u64)
                    .str(",0,32\n");
                out
            }
            3 => out.put(b"MOD,EoM\n"),
            _ => {
                self.modules = 0;
                return;
            }
        };
        self.modules += 1;
    }
}

/// `op` on `motor`'s axis; an error line for a motor the head does not
/// have or that is not (or already) registered.
#[inline(never)]
fn on_motor(curves: &Curves, motor: Motor<'_>, op: Op, out: &mut Out<'_>) {
    let (error, id): (&[u8], &[u8]) = match motor {
        Motor::Unknown(id) => (b"\nerrUnknownMotor: ", id),
        Motor::Axis(axis) => match curves.apply(axis, op) {
            Ok(()) => return,
            Err(MotorError::NotRegistered) => (b"\nerrNoEffectorOnPin: ", axis.name().as_bytes()),
            Err(MotorError::Registered) => (b"\nerrServoCollision: ", axis.name().as_bytes()),
        },
    };
    // Identifiers are at most 8 characters in Bottango.
    out.put(error).put(id.get(..8).unwrap_or(id)).put(b"\n");
}

/// How long a line in progress may pause before the driver answers
/// `TIMEOUT` and drops it, ms (Bottango's driver: 50).
pub const TIMEOUT_MS: u64 = 50;
