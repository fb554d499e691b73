//! One line of Bottango's driver protocol → a [`Command`].
//!
//! A line is a command name and its parameters separated by `,`, the last
//! parameter the hash: `h` and the sum of the bytes before the comma that
//! precedes it, in decimal (`xUC,4,h368`: `x` 120 + `U` 85 + `C` 67 + `,` 44
//! + `4` 52 = 368). Numbers are decimal integers with an optional sign.

use crate::axis::Axis;

/// A motor as Bottango names it: one of the head's axes, or an identifier
/// this head has no motor for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motor<'a> {
    /// `pitch`, `roll` or `yaw`.
    Axis(Axis),
    /// Any other identifier.
    Unknown(&'a [u8]),
}

impl<'a> Motor<'a> {
    fn of(id: &'a [u8]) -> Self {
        Axis::ALL
            .iter()
            .find(|axis| axis.name().as_bytes() == id)
            .map_or(Self::Unknown(id), |axis| Self::Axis(*axis))
    }
}

/// A curve as `sC` sends it: times in ms, movements in 0–8192.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CurveArgs {
    /// Start, ms after the last time sync (`tSYN`).
    pub start: i32,
    /// Duration, ms.
    pub duration: u32,
    /// Movement at the start.
    pub start_y: i32,
    /// The start's control point: ms after the start, and movement relative
    /// to the start's.
    pub start_control: (i32, i32),
    /// Movement at the end.
    pub end_y: i32,
    /// The end's control point: ms relative to the end (usually
    /// negative), movement relative to the end's.
    pub end_control: (i32, i32),
}

/// The signal range of a custom motor (`rMTR`, `upE`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bounds {
    /// The signal at movement 0.
    pub min: i32,
    /// The signal at movement 8192.
    pub max: i32,
    /// The motor's speed limit, signal units per second (not used: the
    /// head's own limits apply).
    pub speed: i32,
}

/// One line of the protocol.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command<'a> {
    /// `hRQ,<code>`: the handshake, with the challenge to repeat.
    Handshake(&'a [u8]),
    /// `hMOD`: which modules the driver has.
    Modules,
    /// `OK`: the app is ready for the next part of a multi-line answer.
    Continue,
    /// `tSYN,<ms>`: the app's clock now.
    TimeSync(u32),
    /// `STOP`: the app stops driving this head.
    Stop,
    /// `xE`: deregister every motor.
    DeregisterAll,
    /// `xUE,<id>`: deregister one.
    Deregister(Motor<'a>),
    /// `xC`: clear every motor's curves.
    ClearAll,
    /// `xUC,<id>`: clear one motor's curves.
    Clear(Motor<'a>),
    /// `rMTR,<id>,<min>,<max>,<speed>,<start>`: register a custom motor
    /// (the start signal is not used: the head starts where it is).
    Register(Motor<'a>, Bounds),
    /// `upE,<id>,<min>,<max>,<speed>`: new signal bounds.
    Bounds(Motor<'a>, Bounds),
    /// `sC,<id>,<start>,<duration>,<y>,<cx>,<cy>,<end y>,<ecx>,<ecy>`.
    Curve(Motor<'a>, CurveArgs),
    /// `sCI,<id>,<movement>`: go there now.
    Instant(Motor<'a>, i32),
    /// A command this driver does not implement (servos on pins,
    /// steppers, events, audio, relays, …): its name.
    Other(&'a [u8]),
}

/// Why a line is not a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineError {
    /// No `,h<sum>` at the end, or the sum does not match.
    Hash,
    /// The hash matches but the parameters do not fit the command: `what`
    /// says which.
    Syntax(&'static str),
}

/// The body of `line` (the bytes before `,h<sum>`) if the hash matches.
///
/// ```
/// use idle_head_core::bottango::checked;
/// assert_eq!(checked(b"xUC,4,h368"), Some(&b"xUC,4"[..]));
/// assert_eq!(checked(b"xUC,4,h369"), None);
/// assert_eq!(checked(b"xUC,4"), None);
/// ```
#[must_use]
pub fn checked(line: &[u8]) -> Option<&[u8]> {
    let comma = line.windows(2).rposition(|w| w == b",h")?;
    let (body, tail) = line.split_at_checked(comma)?;
    let digits = tail.get(2..)?;
    (hash(body) == unsigned(digits)?).then_some(body)
}

/// The sum `line`'s hash must hold: what a sender appends as `,h<sum>`.
#[must_use]
pub fn hash(body: &[u8]) -> u32 {
    body.iter()
        .fold(0, |sum, &b| sum.wrapping_add(u32::from(b)))
}

/// Parses one line (without its line end).
///
/// # Errors
/// [`LineError::Hash`] for a line whose hash is missing or wrong (the
/// driver answers `HASH_FAIL`), [`LineError::Syntax`] for parameters that
/// do not fit the command.
pub fn parse(line: &[u8]) -> Result<Command<'_>, LineError> {
    let body = checked(line).ok_or(LineError::Hash)?;
    let mut args = Args(body.split(|&b| b == b','));
    let name = args.0.next().unwrap_or_default();
    // One comparison loop over a table, not a string comparison per arm.
    let command = match NAMES.iter().position(|n| *n == name) {
        Some(0) => Command::Handshake(args.word("a challenge code")?),
        Some(1) => Command::Modules,
        Some(2) => Command::Continue,
        Some(3) => Command::TimeSync(args.time()?),
        Some(4) => Command::Stop,
        Some(5) => Command::DeregisterAll,
        Some(6) => Command::Deregister(args.motor()?),
        Some(7) => Command::ClearAll,
        Some(8) => Command::Clear(args.motor()?),
        Some(9) => {
            let motor = args.motor()?;
            let bounds = args.bounds()?;
            let _start = args.number()?;
            Command::Register(motor, bounds)
        }
        Some(10) => Command::Bounds(args.motor()?, args.bounds()?),
        Some(11) => {
            let motor = args.motor()?;
            let start = args.number()?;
            let duration = u32::try_from(args.number()?)
                .map_err(|_| LineError::Syntax("a duration of 0 ms or more"))?;
            let start_y = args.number()?;
            let start_control = (args.number()?, args.number()?);
            let end_y = args.number()?;
            let end_control = (args.number()?, args.number()?);
            Command::Curve(
                motor,
                CurveArgs {
                    start,
                    duration,
                    start_y,
                    start_control,
                    end_y,
                    end_control,
                },
            )
        }
        Some(12) => Command::Instant(args.motor()?, args.number()?),
        _ => return Ok(Command::Other(name)),
    };
    // Extra parameters are left alone, as Bottango's own driver does: a
    // newer app may send more.
    Ok(command)
}

/// The handshake's name.
const HANDSHAKE: &[u8] = b"hRQ";

/// Whether `line` starts as a handshake (`hRQ,`) does: a look at its first
/// bytes, before [`parse`] sums its hash.
#[must_use]
pub fn may_be_handshake(line: &[u8]) -> bool {
    line.strip_prefix(HANDSHAKE)
        .is_some_and(|rest| rest.starts_with(b","))
}

/// The commands' names, in the order `parse` matches them.
const NAMES: [&[u8]; 13] = [
    HANDSHAKE, b"hMOD", b"OK", b"tSYN", b"STOP", b"xE", b"xUE", b"xC", b"xUC", b"rMTR", b"upE",
    b"sC", b"sCI",
];

/// The parameters after the command's name.
struct Args<'a, I: Iterator<Item = &'a [u8]>>(I);

impl<'a, I: Iterator<Item = &'a [u8]>> Args<'a, I> {
    fn word(&mut self, what: &'static str) -> Result<&'a [u8], LineError> {
        match self.0.next() {
            Some(word) if !word.is_empty() => Ok(word),
            _ => Err(LineError::Syntax(what)),
        }
    }

    fn motor(&mut self) -> Result<Motor<'a>, LineError> {
        self.word("a motor identifier").map(Motor::of)
    }

    fn number(&mut self) -> Result<i32, LineError> {
        const WHAT: &str = "a whole number";
        let word = self.word(WHAT)?;
        let (negative, digits) = match word.split_first() {
            Some((b'-', rest)) => (true, rest),
            Some((b'+', rest)) => (false, rest),
            _ => (false, word),
        };
        let value = i32::try_from(unsigned(digits).ok_or(LineError::Syntax(WHAT))?)
            .map_err(|_| LineError::Syntax(WHAT))?;
        Ok(if negative { -value } else { value })
    }

    fn time(&mut self) -> Result<u32, LineError> {
        const WHAT: &str = "a time in ms";
        unsigned(self.word(WHAT)?).ok_or(LineError::Syntax(WHAT))
    }

    fn bounds(&mut self) -> Result<Bounds, LineError> {
        Ok(Bounds {
            min: self.number()?,
            max: self.number()?,
            speed: self.number()?,
        })
    }
}

/// 1 to 10 decimal digits that fit a `u32`.
fn unsigned(digits: &[u8]) -> Option<u32> {
    if digits.is_empty() || digits.len() > 10 {
        return None;
    }
    digits.iter().try_fold(0_u32, |value, &d| {
        if !d.is_ascii_digit() {
            return None;
        }
        value.checked_mul(10)?.checked_add(u32::from(d - b'0'))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `body` with its hash, as the app sends it.
    fn signed(body: &str) -> Vec<u8> {
        format!("{body},h{}", hash(body.as_bytes())).into_bytes()
    }

    #[test]
    fn the_documented_example() {
        assert_eq!(
            parse(b"xUC,4,h368"),
            Ok(Command::Clear(Motor::Unknown(b"4")))
        );
    }

    #[test]
    fn every_command() {
        let cases: [(&str, Command<'_>); 12] = [
            ("hRQ,144", Command::Handshake(b"144")),
            ("hMOD", Command::Modules),
            ("OK", Command::Continue),
            ("tSYN,123456", Command::TimeSync(123_456)),
            ("STOP", Command::Stop),
            ("xE", Command::DeregisterAll),
            ("xC", Command::ClearAll),
            ("xUE,yaw", Command::Deregister(Motor::Axis(Axis::Yaw))),
            (
                "rMTR,pitch,-12000,20000,3000,0",
                Command::Register(
                    Motor::Axis(Axis::Pitch),
                    Bounds {
                        min: -12000,
                        max: 20000,
                        speed: 3000,
                    },
                ),
            ),
            (
                "sC,yaw,100,1000,0,250,0,8192,-250,0",
                Command::Curve(
                    Motor::Axis(Axis::Yaw),
                    CurveArgs {
                        start: 100,
                        duration: 1000,
                        start_y: 0,
                        start_control: (250, 0),
                        end_y: 8192,
                        end_control: (-250, 0),
                    },
                ),
            ),
            (
                "sCI,roll,4096",
                Command::Instant(Motor::Axis(Axis::Roll), 4096),
            ),
            ("rSVPin,9,500,2500,3000,1500", Command::Other(b"rSVPin")),
        ];
        for (body, want) in cases {
            assert_eq!(parse(&signed(body)), Ok(want), "{body}");
        }
    }

    #[test]
    fn bad_lines() {
        assert_eq!(parse(b""), Err(LineError::Hash));
        assert_eq!(parse(b"STOP"), Err(LineError::Hash));
        assert_eq!(parse(b"STOP,h0"), Err(LineError::Hash));
        assert_eq!(parse(b",h0"), Ok(Command::Other(b"")));
        assert_eq!(parse(b"STOP,h99999999999"), Err(LineError::Hash));
        for body in [
            "sC,yaw,1,2",
            "tSYN,-5",
            "sCI,yaw,x",
            "rMTR,yaw,1,2",
            "sC,yaw,0,-1,0,0,0,0,0,0",
            "hRQ",
        ] {
            assert!(
                matches!(parse(&signed(body)), Err(LineError::Syntax(_))),
                "{body}"
            );
        }
    }
}
