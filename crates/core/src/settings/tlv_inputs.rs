//! How the inputs' and the rest's settings are written: a switch, the
//! rest timer, a motion command (a button's action) and an input's role.
//!
//! A button's action is kept as the command it parses to, not as its text:
//! 19 bytes at most (a look with all its options) instead of a line, and a
//! record never holds a line the parser of a later firmware might read
//! differently. `input <n>` writes it back as a line (the canonical
//! spelling: `nod 6000 cycles=3`).
//!
//! | value | bytes |
//! |---|---|
//! | switch | 1: 0 off, 1 on |
//! | rest timer | 4: seconds, 0 for `never` |
//! | gesture | 13: 0, the gesture's settings id, which options are given (bit 0 amplitude, 1 duration, 2 cycles, 3 intensity), amplitude (4, m°), duration (4, ms), cycles, intensity |
//! | look | 19: 1, given (bit 0 duration, 1 hold), pitch (4), yaw (4), duration (4), hold (5, as `gaze.hold`) |
//! | center | 6: 2, given (bit 0 duration), duration (4) |
//! | idle on, off | 2: 3, 1 or 0 |
//! | idle amp | 2: 4, the percentage |
//! | stop, rest | 1: 5, 6 |
//! | wake | 1: 7 (or 5: 7 and a yaw, m°) |
//! | role | 1: 0 off; 1 and an action: button; 1: 2, presence; 5: 2 and a yaw, presence with a direction |
//!
//! Options not given are written as zeros; an unknown tag, a wrong length,
//! a percentage over 100, a zero count of cycles or duration, a gesture's
//! duration without its amplitude (a line cannot say that) or an unknown
//! gesture is no value.

use crate::command::{
    Action, GestureKind, GestureRequest, Hold, InputRole, LookRequest, Percent, RestAfter,
};
use crate::units::{Angle, Millis};

use super::tlv::{FieldValue, put, u32_of};

impl FieldValue for RestAfter {
    const MAX_LEN: usize = 4;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        let seconds = match self {
            Self::Never => 0,
            Self::Seconds(s) => *s,
        };
        put(out, &seconds.to_le_bytes())
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        match u32_of(bytes)? {
            0 => Some(Self::Never),
            s => Self::seconds(s),
        }
    }
}

/// Most bytes an action takes: a look.
const ACTION_LEN: usize = 19;

/// A writer of a fixed-length value.
struct Bytes {
    buf: [u8; ACTION_LEN],
    len: usize,
}

impl Bytes {
    const fn new() -> Self {
        Self {
            buf: [0; ACTION_LEN],
            len: 0,
        }
    }

    fn byte(&mut self, b: u8) -> &mut Self {
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = b;
        }
        self.len += 1;
        self
    }

    fn word(&mut self, w: u32) -> &mut Self {
        for b in w.to_le_bytes() {
            self.byte(b);
        }
        self
    }

    /// `value` as its field is stored ([`FieldValue`]).
    fn value<T: FieldValue>(&mut self, value: &T) -> &mut Self {
        let mut bytes = [0; 8];
        let n = value.to_bytes(&mut bytes);
        for &b in bytes.get(..n).unwrap_or_default() {
            self.byte(b);
        }
        self
    }

    fn bytes(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or_default()
    }
}

/// A reader of a value's bytes, field by field.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn byte(&mut self) -> Option<u8> {
        let (&b, rest) = self.0.split_first()?;
        self.0 = rest;
        Some(b)
    }

    fn word(&mut self) -> Option<u32> {
        let (word, rest) = self.0.split_at_checked(4)?;
        self.0 = rest;
        u32_of(word)
    }

    fn angle(&mut self) -> Option<Angle> {
        let (bytes, rest) = self.0.split_at_checked(<Angle as FieldValue>::MAX_LEN)?;
        self.0 = rest;
        Angle::from_bytes(bytes)
    }

    /// An angle that ends the value, if it is there (a wake's or a presence
    /// sensor's direction); `Err` for bytes that are no angle.
    fn optional_angle(&mut self) -> Result<Option<Angle>, ()> {
        if self.0.is_empty() {
            Ok(None)
        } else {
            self.angle().map(Some).ok_or(())
        }
    }

    /// The value, if nothing is left over.
    fn end<T>(&self, value: T) -> Option<T> {
        self.0.is_empty().then_some(value)
    }
}

/// `value` if `given`.
fn given<T>(given: bool, value: T) -> Option<T> {
    given.then_some(value)
}

fn write_action(action: &Action, b: &mut Bytes) {
    match *action {
        Action::Gesture(g) => {
            let mask = u8::from(g.amplitude.is_some())
                | u8::from(g.duration.is_some()) << 1
                | u8::from(g.cycles.is_some()) << 2
                | u8::from(g.intensity.is_some()) << 3;
            b.byte(0).byte(g.kind.row().settings).byte(mask);
            b.value(&g.amplitude.unwrap_or(Angle::ZERO));
            b.word(g.duration.unwrap_or(Millis(0)).0);
            b.byte(g.cycles.unwrap_or(0));
            b.byte(g.intensity.map_or(0, Percent::get));
        }
        Action::Look(l) => {
            let mask = u8::from(l.duration.is_some()) | u8::from(l.hold.is_some()) << 1;
            b.byte(1).byte(mask);
            b.value(&l.pitch).value(&l.yaw);
            b.word(l.duration.unwrap_or(Millis(0)).0);
            b.value(&l.hold.unwrap_or(Hold::Return(Millis(0))));
        }
        Action::Center { duration } => {
            b.byte(2).byte(u8::from(duration.is_some()));
            b.word(duration.unwrap_or(Millis(0)).0);
        }
        Action::Idle(on) => {
            b.byte(3).byte(u8::from(on));
        }
        Action::IdleAmp(p) => {
            b.byte(4).byte(p.get());
        }
        Action::Stop => {
            b.byte(5);
        }
        Action::Rest => {
            b.byte(6);
        }
        Action::Wake { toward } => {
            b.byte(7);
            if let Some(yaw) = toward {
                b.value(&yaw);
            }
        }
    }
}

fn read_action(r: &mut Reader<'_>) -> Option<Action> {
    let action = match r.byte()? {
        0 => {
            let id = r.byte()?;
            let kind = *GestureKind::ALL.iter().find(|k| k.row().settings == id)?;
            let mask = r.byte()?;
            let (amplitude, duration) = (r.angle()?, Millis(r.word()?));
            let (cycles, intensity) = (r.byte()?, r.byte()?);
            // As a line has them: a duration only after an amplitude.
            if mask > 0b1111
                || (mask & 4 != 0 && cycles == 0)
                || (mask & 2 != 0 && (duration.0 == 0 || mask & 1 == 0))
            {
                return None;
            }
            let intensity = if mask & 8 != 0 {
                Some(Percent::new(intensity)?)
            } else {
                None
            };
            Action::Gesture(GestureRequest {
                kind,
                amplitude: given(mask & 1 != 0, amplitude),
                duration: given(mask & 2 != 0, duration),
                cycles: given(mask & 4 != 0, cycles),
                intensity,
            })
        }
        1 => {
            let mask = r.byte()?;
            let (pitch, yaw, duration) = (r.angle()?, r.angle()?, Millis(r.word()?));
            let hold = Hold::from_bytes(r.0.get(..5)?)?;
            r.0 = r.0.get(5..)?;
            if mask > 0b11 || (mask & 1 != 0 && duration.0 == 0) {
                return None;
            }
            Action::Look(LookRequest {
                pitch,
                yaw,
                duration: given(mask & 1 != 0, duration),
                hold: given(mask & 2 != 0, hold),
            })
        }
        2 => {
            let mask = r.byte()?;
            let duration = Millis(r.word()?);
            if mask > 1 || (mask == 1 && duration.0 == 0) {
                return None;
            }
            Action::Center {
                duration: given(mask == 1, duration),
            }
        }
        3 => Action::Idle(bool::from_bytes(&[r.byte()?])?),
        4 => Action::IdleAmp(Percent::new(r.byte()?)?),
        5 => Action::Stop,
        6 => Action::Rest,
        7 => Action::Wake {
            toward: r.optional_angle().ok()?,
        },
        _ => return None,
    };
    Some(action)
}

impl FieldValue for Action {
    const MAX_LEN: usize = ACTION_LEN;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        let mut b = Bytes::new();
        write_action(self, &mut b);
        put(out, b.bytes())
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let mut r = Reader(bytes);
        let action = read_action(&mut r)?;
        r.end(action)
    }
}

impl FieldValue for InputRole {
    const MAX_LEN: usize = 1 + ACTION_LEN;

    fn to_bytes(&self, out: &mut [u8]) -> usize {
        let mut b = Bytes::new();
        let tag: &[u8] = match self {
            Self::Off => &[0],
            Self::Button(action) => {
                write_action(action, &mut b);
                &[1]
            }
            Self::Presence { toward } => {
                if let Some(yaw) = toward {
                    b.value(yaw);
                }
                &[2]
            }
        };
        let n = put(out, tag);
        n + out.get_mut(n..).map_or(0, |rest| put(rest, b.bytes()))
    }

    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let (&tag, rest) = bytes.split_first()?;
        let mut r = Reader(rest);
        let role = match tag {
            0 => Self::Off,
            1 => Self::Button(read_action(&mut r)?),
            2 => Self::Presence {
                toward: r.optional_angle().ok()?,
            },
            _ => return None,
        };
        r.end(role)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip<T: FieldValue + PartialEq + Copy + core::fmt::Debug>(value: T) -> Vec<u8> {
        let mut out = [0xee; 32];
        let n = value.to_bytes(&mut out);
        assert!(n <= T::MAX_LEN, "{value:?}: {n} bytes");
        assert_eq!(T::from_bytes(&out[..n]), Some(value));
        // Cut short or grown, it is not that value (a wake cut before its
        // direction is a wake without one).
        for cut in 0..n {
            assert_ne!(
                T::from_bytes(&out[..cut]),
                Some(value),
                "{value:?} cut at {cut}"
            );
        }
        let mut long = out[..n].to_vec();
        long.push(0);
        assert_eq!(T::from_bytes(&long), None, "{value:?} grown");
        out[..n].to_vec()
    }

    fn actions() -> Vec<Action> {
        let mut all = vec![
            Action::Look(LookRequest {
                pitch: Angle::from_millidegrees(-8000),
                yaw: Angle::from_millidegrees(i32::MAX),
                duration: Some(Millis(1)),
                hold: Some(Hold::Stay),
            }),
            Action::Look(LookRequest {
                pitch: Angle::ZERO,
                yaw: Angle::from_millidegrees(-1),
                duration: None,
                hold: Some(Hold::Return(Millis(2500))),
            }),
            Action::Center { duration: None },
            Action::Center {
                duration: Some(Millis(700)),
            },
            Action::Idle(true),
            Action::Idle(false),
            Action::IdleAmp(Percent::HALF),
            Action::Stop,
            Action::Rest,
            Action::Wake { toward: None },
            Action::Wake {
                toward: Some(Angle::from_degrees(-20)),
            },
        ];
        for kind in GestureKind::ALL {
            all.push(Action::Gesture(GestureRequest::new(kind)));
            let mut amplitude = GestureRequest::new(kind);
            amplitude.amplitude = Some(Angle::from_millidegrees(4000));
            all.push(Action::Gesture(amplitude));
            all.push(Action::Gesture(GestureRequest {
                kind,
                amplitude: Some(Angle::from_millidegrees(-6000)),
                duration: Some(Millis(900)),
                cycles: Some(3),
                intensity: Percent::new(70),
            }));
        }
        all
    }

    #[test]
    fn every_action_and_role_round_trips() {
        for action in actions() {
            round_trip(action);
            round_trip(InputRole::Button(action));
        }
        assert_eq!(round_trip(InputRole::Off), [0]);
        assert_eq!(round_trip(InputRole::Presence { toward: None }), [2]);
        assert_eq!(
            round_trip(InputRole::Presence {
                toward: Some(Angle::from_millidegrees(-2))
            }),
            [2, 0xfe, 0xff, 0xff, 0xff]
        );
        assert_eq!(round_trip(Action::Rest), [6]);
        assert_eq!(round_trip(Action::IdleAmp(Percent::HALF)), [4, 50]);
        assert_eq!(round_trip(RestAfter::Never), [0, 0, 0, 0]);
        assert_eq!(round_trip(RestAfter::Seconds(120)), [120, 0, 0, 0]);
        assert_eq!(round_trip(true), [1]);
        assert_eq!(round_trip(false), [0]);
    }

    #[test]
    fn bytes_that_are_no_value_are_refused() {
        let nod = GestureKind::Nod.row().settings;
        for bad in [
            &[9][..],                                     // no such action
            &[0, 200, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],   // no such gesture
            &[0, nod, 16, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],  // an unknown option
            &[0, nod, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],   // zero cycles given
            &[0, nod, 8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 101], // 101 %
            &[2, 1, 0, 0, 0, 0],                          // a duration of 0 given
            &[0, nod, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0],   // a duration, no amplitude
            &[3, 2],                                      // idle neither on nor off
            &[4, 101],                                    // idle amp 101 %
        ] {
            assert_eq!(Action::from_bytes(bad), None, "{bad:?}");
        }
        // Fixed lengths: one byte short is nothing.
        let mut look = [0; 19];
        let n = actions()[0].to_bytes(&mut look);
        assert_eq!(Action::from_bytes(&look[..n - 1]), None);
        assert_eq!(InputRole::from_bytes(&[3]), None);
        assert_eq!(InputRole::from_bytes(&[2, 0, 0]), None);
        assert_eq!(RestAfter::from_bytes(&86_401_u32.to_le_bytes()), None);
        assert_eq!(bool::from_bytes(&[2]), None);
    }
}
