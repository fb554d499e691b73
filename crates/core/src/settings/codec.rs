//! [`Settings`] as a [`Record`]: fixed-width little-endian integers, no
//! floats, no field names.
//!
//! Layout of version 1 (192 bytes), in order:
//!
//! | part | fields (bytes) |
//! |---|---|
//! | each servo, pitch, roll, yaw | neutral µs (4), per-degree ns (4), direction 0 normal / 1 reversed (1), min µs (4), max µs (4), limits min, max mdeg (4, 4 signed) |
//! | each gesture, in the order of `GestureKind::ALL` (nod, shake, tilt) | amplitude mdeg (4 signed), cycles (1), slow mHz (4), brisk mHz (4), intensity % (1) |
//! | gestures | max frequency mHz (4), longest gesture ms (4), blend ms (4) |
//! | gaze | base ms (4), per degree ms (4), hold 0 return / 1 stay (1) and ms (4), longest ms (4) |
//! | idle | amplitude % (1), duck % (1), fade ms (4) |
//! | gesture limits, each axis | speed °/s (4), acceleration °/s² (4) |
//! | settle | ms (4) |
//! | seeds, each axis | (4) |
//!
//! A decoded record is validated against the built-in driver
//! configuration ([`Settings::validate`] with [`DriverConfig::DEFAULT`]):
//! bytes that decode to settings the firmware would refuse are
//! [`DecodeError::Invalid`].

use crate::behaviour::{GazeConfig, GestureDefaults, IdleConfig, MilliHertz};
use crate::command::{Hold, Percent};
use crate::driver::{DegreesPerSecond, DegreesPerSecondSquared, DriverConfig, MotionLimits};
use crate::gestures::GestureKind;
use crate::servo::{Direction, NanosPerDegree, ServoCalibration};
use crate::units::{Angle, AngleRange, Microseconds, Millis};

use super::record::{DecodeError, EncodeError, Record};
use super::values::Settings;

/// Bytes of a version 1 record.
pub const SETTINGS_LEN: usize = 3 * 25 + GestureKind::COUNT * 14 + 12 + 17 + 6 + 3 * 8 + 4 + 3 * 4;

impl Record for Settings {
    const VERSION: u16 = 1;

    fn encode(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer {
            buf,
            len: 0,
            full: false,
        };
        for s in &self.servos {
            w.u32(s.neutral.0);
            w.u32(s.per_degree.0);
            w.u8(match s.direction {
                Direction::Normal => 0,
                Direction::Reversed => 1,
            });
            w.u32(s.min_pulse.0);
            w.u32(s.max_pulse.0);
            w.i32(s.limits.min.millidegrees());
            w.i32(s.limits.max.millidegrees());
        }
        let b = &self.behaviour;
        for g in &b.gestures {
            w.i32(g.amplitude.millidegrees());
            w.u8(g.cycles);
            w.u32(g.slow.0);
            w.u32(g.brisk.0);
            w.u8(g.intensity.get());
        }
        w.u32(b.max_frequency.0);
        w.u32(b.longest_gesture.0);
        w.u32(b.blend.0);
        w.u32(b.gaze.base.0);
        w.u32(b.gaze.per_degree.0);
        match b.gaze.hold {
            Hold::Return(ms) => {
                w.u8(0);
                w.u32(ms.0);
            }
            Hold::Stay => {
                w.u8(1);
                w.u32(0);
            }
        }
        w.u32(b.gaze.longest.0);
        w.u8(b.idle.amplitude.get());
        w.u8(b.idle.duck.get());
        w.u32(b.idle.fade.0);
        for l in &b.gesture_limits {
            w.u32(l.max_speed.0);
            w.u32(l.max_accel.0);
        }
        w.u32(b.settle.0);
        for seed in self.seeds {
            w.u32(seed);
        }
        w.finish()
    }

    fn decode(bytes: &[u8]) -> Result<Self, DecodeError> {
        let mut r = Reader {
            bytes,
            malformed: false,
        };
        let mut settings = Self::DEFAULT;
        for s in &mut settings.servos {
            *s = ServoCalibration {
                neutral: Microseconds(r.u32()),
                per_degree: NanosPerDegree(r.u32()),
                direction: match r.u8() {
                    0 => Direction::Normal,
                    1 => Direction::Reversed,
                    _ => return Err(DecodeError::Malformed),
                },
                min_pulse: Microseconds(r.u32()),
                max_pulse: Microseconds(r.u32()),
                limits: AngleRange {
                    min: Angle::from_millidegrees(r.i32()),
                    max: Angle::from_millidegrees(r.i32()),
                },
            };
        }
        let b = &mut settings.behaviour;
        for g in &mut b.gestures {
            *g = GestureDefaults {
                amplitude: Angle::from_millidegrees(r.i32()),
                cycles: r.u8(),
                slow: MilliHertz(r.u32()),
                brisk: MilliHertz(r.u32()),
                intensity: r.percent(),
            };
        }
        b.max_frequency = MilliHertz(r.u32());
        b.longest_gesture = Millis(r.u32());
        b.blend = Millis(r.u32());
        let base = Millis(r.u32());
        let per_degree = Millis(r.u32());
        let hold = match (r.u8(), r.u32()) {
            (0, ms) => Hold::Return(Millis(ms)),
            (1, 0) => Hold::Stay,
            _ => return Err(DecodeError::Malformed),
        };
        b.gaze = GazeConfig {
            base,
            per_degree,
            hold,
            longest: Millis(r.u32()),
        };
        b.idle = IdleConfig {
            amplitude: r.percent(),
            duck: r.percent(),
            fade: Millis(r.u32()),
        };
        for l in &mut b.gesture_limits {
            *l = MotionLimits {
                max_speed: DegreesPerSecond(r.u32()),
                max_accel: DegreesPerSecondSquared(r.u32()),
            };
        }
        b.settle = Millis(r.u32());
        for seed in &mut settings.seeds {
            *seed = r.u32();
        }
        if r.malformed || !r.bytes.is_empty() {
            return Err(DecodeError::Malformed);
        }
        match settings.validate(&DriverConfig::DEFAULT) {
            Ok(_) => Ok(settings),
            Err(_) => Err(DecodeError::Invalid),
        }
    }
}

// The fields are written and read by calls, not inlined, and a short
// buffer is remembered and reported once at the end instead of at every
// field: the codec runs at boot and on `save` only, and this halves its
// flash.

struct Writer<'a> {
    buf: &'a mut [u8],
    len: usize,
    /// A field did not fit.
    full: bool,
}

impl Writer<'_> {
    #[inline(never)]
    fn put(&mut self, bytes: &[u8]) {
        let end = self.len + bytes.len();
        if let Some(slot) = self.buf.get_mut(self.len..end) {
            slot.copy_from_slice(bytes);
            self.len = end;
        } else {
            self.full = true;
        }
    }

    fn u8(&mut self, v: u8) {
        self.put(&[v]);
    }

    #[inline(never)]
    fn u32(&mut self, v: u32) {
        self.put(&v.to_le_bytes());
    }

    fn i32(&mut self, v: i32) {
        self.u32(v.cast_unsigned());
    }

    /// The bytes written, or `TooLong` if a field did not fit.
    fn finish(self) -> Result<usize, EncodeError> {
        if self.full {
            Err(EncodeError::TooLong)
        } else {
            Ok(self.len)
        }
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    /// A field was missing or out of its range.
    malformed: bool,
}

impl Reader<'_> {
    #[inline(never)]
    fn take<const N: usize>(&mut self) -> [u8; N] {
        if let Some((head, rest)) = self.bytes.split_first_chunk::<N>() {
            self.bytes = rest;
            *head
        } else {
            self.malformed = true;
            [0; N]
        }
    }

    #[inline(never)]
    fn u8(&mut self) -> u8 {
        let [b] = self.take::<1>();
        b
    }

    #[inline(never)]
    fn percent(&mut self) -> Percent {
        Percent::new(self.u8()).unwrap_or_else(|| {
            self.malformed = true;
            Percent::FULL
        })
    }

    #[inline(never)]
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }

    fn i32(&mut self) -> i32 {
        self.u32().cast_signed()
    }
}
