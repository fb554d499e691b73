//! Commands as text: random commands, and their text in the protocol (with
//! the variations a person or a program may type).

use std::fmt::Write as _;

use idle_head_core::command::{
    Action, Command, DmxSetting, GestureKind, GestureRequest, Hold, InputRole, LookRequest,
    Percent, RestAfter, RestSetting, SeedChoice, ServoSetting, TrackSetting,
};
use idle_head_core::console::KEYWORDS;
use idle_head_core::dmx::DmxAddress;
use idle_head_core::servo::{Direction, NanosPerDegree, ServoRate};
use idle_head_core::track::Prefer;
use idle_head_core::{Angle, AngleRange, Axis, Microseconds, Millimetres, Millis};
use proptest::prelude::RngExt as _;
use proptest::test_runner::TestRng;

/// The fuzz's words beyond the protocol's keywords ([`KEYWORDS`]) and the
/// gestures' ([`GestureKind::ALL`]'s): options as typed, with their `=`.
pub const VOCABULARY: &[&str] = &["hold=", "cycles=", "intensity=", "hold=stay", "="];

/// A random word of the protocol: one of [`KEYWORDS`], a gesture's, or one
/// of [`VOCABULARY`]; so a keyword added to the parser is fuzzed at once.
pub fn vocabulary_word(rng: &mut TestRng) -> &'static str {
    let i = rng.random_range(0..KEYWORDS.len() + GestureKind::COUNT + VOCABULARY.len());
    if let Some(word) = KEYWORDS.get(i) {
        return word;
    }
    let i = i - KEYWORDS.len();
    if let Some(kind) = GestureKind::ALL.get(i) {
        return kind.name();
    }
    VOCABULARY[i - GestureKind::COUNT]
}

/// Numbers at and past the limits of every field.
pub const EDGE_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "+0",
    "1",
    "-1",
    "50",
    "51",
    "100",
    "101",
    "255",
    "256",
    "2147483647",
    "2147483648",
    "-2147483647",
    "-2147483648",
    "-2147483649",
    "4294967295",
    "4294967296",
    "4611686018427387904",
    "4611686018427387905",
    "9223372036854775807",
    "9223372036854775808",
    "-9223372036854775808",
    "99999999999999999999999",
    "000000000000000000000007",
    "+",
    "-",
    "--1",
    "+-1",
    "1e3",
    "0x10",
    "١٢",
];

/// A value from `edges` most of the time, else anything in `lo..=hi`.
fn pick_i64(rng: &mut TestRng, lo: i64, hi: i64, edges: &[i64]) -> i64 {
    if rng.random_bool(0.3) {
        let e = edges[rng.random_range(0..edges.len())];
        return e.clamp(lo, hi);
    }
    rng.random_range(lo..=hi)
}

fn angle(rng: &mut TestRng) -> Angle {
    let v = pick_i64(
        rng,
        i64::from(i32::MIN) + 1,
        i64::from(i32::MAX),
        &[i64::from(i32::MIN) + 1, -1, 0, 1, i64::from(i32::MAX)],
    );
    if rng.random_bool(0.5) {
        // Mostly head-sized angles.
        return Angle::from_millidegrees(rng.random_range(-60_000..=60_000));
    }
    Angle::from_millidegrees(v as i32)
}

fn millis(rng: &mut TestRng, min: u32) -> Millis {
    let v = pick_i64(
        rng,
        i64::from(min),
        i64::from(u32::MAX),
        &[i64::from(min), 1, i64::from(u32::MAX)],
    );
    Millis(v as u32)
}

fn u32_any(rng: &mut TestRng) -> u32 {
    pick_i64(rng, 0, i64::from(u32::MAX), &[0, 1, i64::from(u32::MAX)]) as u32
}

fn percent(rng: &mut TestRng) -> Percent {
    Percent::new(rng.random_range(0..=100)).unwrap_or(Percent::FULL)
}

fn maybe<T>(rng: &mut TestRng, f: impl FnOnce(&mut TestRng) -> T) -> Option<T> {
    if rng.random_bool(0.5) {
        Some(f(rng))
    } else {
        None
    }
}

/// A random motion command, every field anywhere in its parseable range.
pub fn random_action(rng: &mut TestRng) -> Action {
    match rng.random_range(0..7) {
        0 => Action::Stop,
        1 => {
            let kind = GestureKind::ALL[rng.random_range(0..GestureKind::COUNT)];
            let mut g = GestureRequest::new(kind);
            g.amplitude = maybe(rng, angle);
            if g.amplitude.is_some() {
                g.duration = maybe(rng, |r| millis(r, 1));
            }
            if kind.row().max_cycles > 1 {
                g.cycles = maybe(rng, |r| r.random_range(1..=255));
            }
            g.intensity = maybe(rng, percent);
            Action::Gesture(g)
        }
        2 => Action::Look(LookRequest {
            pitch: angle(rng),
            yaw: angle(rng),
            duration: maybe(rng, |r| millis(r, 1)),
            hold: maybe(rng, |r| {
                if r.random_bool(0.3) {
                    Hold::Stay
                } else {
                    Hold::Return(millis(r, 0))
                }
            }),
        }),
        3 => Action::Center {
            duration: maybe(rng, |r| millis(r, 1)),
        },
        4 => match rng.random_range(0..3) {
            0 => Action::Idle(true),
            1 => Action::Idle(false),
            _ => Action::IdleAmp(percent(rng)),
        },
        5 => Action::Rest,
        _ => Action::Wake { toward: None },
    }
}

/// A random command, every field anywhere in its parseable range.
pub fn random_command(rng: &mut TestRng) -> Command {
    // Motion about half the time, as a show controller sends it.
    match rng.random_range(0..22) {
        21 => Command::ServoRate(maybe(rng, |r| {
            let hz = pick_i64(r, 50, 333, &[50, 51, 200, 332, 333]) as u16;
            ServoRate::new(hz).unwrap_or(ServoRate::DEFAULT)
        })),
        14 => Command::Watch(maybe(rng, |r| r.random_range(1..=50))),
        0 => Command::Help,
        1 => Command::Status,
        2 => Command::Save,
        3 => Command::Load,
        4 => Command::Defaults,
        5..=9 | 16..=20 => Command::Act(random_action(rng)),
        12 => Command::Input {
            input: rng.random_range(2..=5),
            role: maybe(rng, |r| match r.random_range(0..3) {
                0 => InputRole::Off,
                1 => InputRole::Button(random_action(r)),
                _ => InputRole::Presence {
                    toward: maybe(r, angle),
                },
            }),
        },
        13 => match rng.random_range(0..7) {
            0 => Command::Rest(Some(RestSetting::After(if rng.random_bool(0.2) {
                RestAfter::Never
            } else {
                RestAfter::Seconds(rng.random_range(1..=86_400))
            }))),
            1 => Command::Rest(Some(RestSetting::Pose([
                angle(rng),
                angle(rng),
                angle(rng),
            ]))),
            2 => Command::Rest(Some(RestSetting::Relax(rng.random_bool(0.5)))),
            3 => Command::Rest(None),
            4 => Command::IdleQuery,
            _ => Command::LookDuck(maybe(rng, percent)),
        },
        10 => match rng.random_range(0..10) {
            0 => Command::Seed(SeedChoice::Random),
            1 => Command::Seed(SeedChoice::Board),
            2 => Command::Seed(SeedChoice::Paper),
            3 => Command::SeedQuery,
            4 => Command::Radar(maybe(rng, |r| r.random_bool(0.5))),
            5 => Command::Track(maybe(rng, |r| match r.random_range(0..4) {
                0 => TrackSetting::Gaze(r.random_bool(0.5)),
                1 => TrackSetting::Height(Millimetres(r.random_range(-3000..=3000))),
                2 => TrackSetting::Mount(Angle::from_millidegrees(
                    r.random_range(-180_000..=180_000),
                )),
                _ => TrackSetting::Prefer(if r.random_bool(0.5) {
                    Prefer::Nearest
                } else {
                    Prefer::Newest
                }),
            })),
            _ => Command::Seed(SeedChoice::Value(u32_any(rng))),
        },
        11 => Command::Dmx(maybe(rng, |r| match r.random_range(0..3) {
            0 => DmxSetting::On(true),
            1 => DmxSetting::On(false),
            _ => {
                let slot = pick_i64(r, 1, 503, &[1, 2, 502, 503]) as u16;
                DmxSetting::Address(DmxAddress::new(slot).unwrap_or(DmxAddress::FIRST))
            }
        })),
        _ => Command::Servo {
            axis: Axis::ALL[rng.random_range(0..3)],
            setting: maybe(rng, |r| match r.random_range(0..6) {
                0 => ServoSetting::Neutral(Microseconds(u32_any(r))),
                1 => ServoSetting::PerDegree(NanosPerDegree(u32_any(r))),
                2 => ServoSetting::Direction(if r.random_bool(0.5) {
                    Direction::Normal
                } else {
                    Direction::Reversed
                }),
                3 => ServoSetting::MinPulse(Microseconds(u32_any(r))),
                4 => ServoSetting::MaxPulse(Microseconds(u32_any(r))),
                _ => ServoSetting::Limits(AngleRange {
                    min: angle(r),
                    max: angle(r),
                }),
            }),
        },
    }
}

/// How to spell a command: canonical (no generator), or with the
/// variations the grammar allows (case, blanks, signs, leading zeros,
/// option order, `centre`).
struct Style<'r> {
    rng: Option<&'r mut TestRng>,
    out: String,
}

impl Style<'_> {
    fn chance(&mut self, p: f64) -> bool {
        self.rng.as_mut().is_some_and(|r| r.random_bool(p))
    }

    fn word(&mut self, word: &str) {
        self.blank();
        for c in word.chars() {
            let upper = self.chance(0.2);
            self.out
                .push(if upper { c.to_ascii_uppercase() } else { c });
        }
    }

    fn number(&mut self, v: i64) {
        self.blank();
        if v < 0 {
            self.out.push('-');
        } else if self.chance(0.1) {
            self.out.push('+');
        }
        while self.chance(0.1) {
            self.out.push('0');
        }
        write!(self.out, "{}", v.unsigned_abs()).unwrap();
    }

    fn millis(&mut self, m: Millis) {
        self.number(i64::from(m.0));
    }

    fn mdeg(&mut self, a: Angle) {
        self.number(i64::from(a.millidegrees()));
    }

    fn option(&mut self, name: &str, value: &str) {
        self.word(name);
        self.out.push('=');
        self.out.push_str(value);
    }

    fn blank(&mut self) {
        let first = self.out.is_empty();
        let Some(rng) = self.rng.as_mut() else {
            if !first {
                self.out.push(' ');
            }
            return;
        };
        let n = if first {
            rng.random_range(0..2)
        } else {
            rng.random_range(1..3)
        };
        for _ in 0..n {
            let c = if rng.random_bool(0.8) { ' ' } else { '\t' };
            self.out.push(c);
        }
    }
}

/// The canonical text of `command`: the parser reads it back as `command`.
#[must_use]
pub fn command_text(command: &Command) -> String {
    let mut style = Style {
        rng: None,
        out: String::new(),
    };
    write_command(&mut style, command);
    style.out
}

/// The text of `command` spelled with random variations of case, blanks,
/// signs, leading zeros and option order; it still parses as `command`.
pub fn varied_text(command: &Command, rng: &mut TestRng) -> String {
    let mut style = Style {
        rng: Some(rng),
        out: String::new(),
    };
    write_command(&mut style, command);
    while style.chance(0.3) {
        style.out.push(' ');
    }
    style.out
}

fn write_command(s: &mut Style<'_>, command: &Command) {
    match *command {
        Command::Help => s.word("help"),
        Command::Status => s.word("status"),
        Command::Save => s.word("save"),
        Command::Load => s.word("load"),
        Command::Defaults => s.word("defaults"),
        Command::Act(action) => write_action(s, &action),
        Command::Input { input, role } => {
            s.word("input");
            s.number(i64::from(input));
            match role {
                None => {}
                Some(InputRole::Off) => s.word("off"),
                Some(InputRole::Button(action)) => {
                    s.word("button");
                    write_action(s, &action);
                }
                Some(InputRole::Presence { toward }) => {
                    s.word("presence");
                    if let Some(yaw) = toward {
                        s.mdeg(yaw);
                    }
                }
            }
        }
        Command::Rest(setting) => {
            s.word("rest");
            let Some(setting) = setting else {
                // Any of the three fields alone shows them all.
                let field = match s.rng.as_mut().map_or(0, |r| r.random_range(0..3)) {
                    0 => "after",
                    1 => "pose",
                    _ => "relax",
                };
                s.word(field);
                return;
            };
            match setting {
                RestSetting::After(RestAfter::Never) => {
                    s.word("after");
                    s.word("never");
                }
                RestSetting::After(RestAfter::Seconds(n)) => {
                    s.word("after");
                    s.number(i64::from(n));
                }
                RestSetting::Pose(pose) => {
                    s.word("pose");
                    for a in pose {
                        s.mdeg(a);
                    }
                }
                RestSetting::Relax(on) => {
                    s.word("relax");
                    s.word(if on { "on" } else { "off" });
                }
            }
        }
        Command::LookDuck(p) => {
            s.word("look");
            s.word("duck");
            if let Some(p) = p {
                s.number(i64::from(p.get()));
            }
        }
        Command::IdleQuery => s.word("idle"),
        Command::Seed(SeedChoice::Random) => {
            s.word("seed");
            s.word("random");
        }
        Command::Seed(SeedChoice::Value(v)) => {
            s.word("seed");
            s.number(i64::from(v));
        }
        Command::Seed(SeedChoice::Board) => {
            s.word("seed");
            s.word("board");
        }
        Command::Seed(SeedChoice::Paper) => {
            s.word("seed");
            s.word("paper");
        }
        Command::SeedQuery => s.word("seed"),
        Command::Radar(on) => {
            s.word("radar");
            if let Some(on) = on {
                s.word(if on { "on" } else { "off" });
            }
        }
        Command::Track(setting) => {
            s.word("track");
            match setting {
                None => {}
                Some(TrackSetting::Gaze(on)) => s.word(if on { "on" } else { "off" }),
                Some(TrackSetting::Height(mm)) => {
                    s.word("height");
                    s.number(i64::from(mm.0));
                }
                Some(TrackSetting::Mount(yaw)) => {
                    s.word("mount");
                    s.mdeg(yaw);
                }
                Some(TrackSetting::Prefer(p)) => {
                    s.word("prefer");
                    s.word(p.word());
                }
            }
        }
        Command::Watch(None) => {
            s.word("watch");
            s.word("off");
        }
        Command::Watch(Some(hz)) => {
            s.word("watch");
            s.number(i64::from(hz));
        }
        Command::ServoRate(rate) => {
            s.word("servo");
            s.word("rate");
            if let Some(rate) = rate {
                s.number(i64::from(rate.hz()));
            }
        }
        Command::Servo { axis, setting } => {
            s.word("servo");
            s.word(axis.name());
            let Some(setting) = setting else { return };
            s.word(setting.field());
            match setting {
                ServoSetting::Neutral(us)
                | ServoSetting::MinPulse(us)
                | ServoSetting::MaxPulse(us) => s.number(i64::from(us.0)),
                ServoSetting::PerDegree(ns) => s.number(i64::from(ns.0)),
                ServoSetting::Direction(Direction::Normal) => s.word("normal"),
                ServoSetting::Direction(Direction::Reversed) => s.word("reversed"),
                ServoSetting::Limits(r) => {
                    s.mdeg(r.min);
                    s.mdeg(r.max);
                }
            }
        }
        Command::Dmx(setting) => {
            s.word("dmx");
            match setting {
                None => {}
                Some(DmxSetting::On(on)) => s.word(if on { "on" } else { "off" }),
                Some(DmxSetting::Address(a)) => {
                    s.word("address");
                    s.number(i64::from(a.get()));
                }
            }
        }
    }
}

/// The text of a motion command.
fn write_action(s: &mut Style<'_>, action: &Action) {
    match *action {
        Action::Stop => s.word("stop"),
        Action::Rest => s.word("rest"),
        // A direction comes from a presence input, never from a line.
        Action::Wake { .. } => s.word("wake"),
        Action::Gesture(g) => {
            s.word(g.kind.name());
            if let Some(a) = g.amplitude {
                s.mdeg(a);
                if let Some(d) = g.duration {
                    s.millis(d);
                }
            }
            let mut options = Vec::new();
            if let Some(c) = g.cycles {
                options.push(("cycles", c.to_string()));
            }
            if let Some(i) = g.intensity {
                options.push(("intensity", i.get().to_string()));
            }
            if s.chance(0.5) {
                options.reverse();
            }
            for (name, value) in options {
                s.option(name, &value);
            }
        }
        Action::Look(l) => {
            s.word("look");
            s.mdeg(l.pitch);
            s.mdeg(l.yaw);
            if let Some(d) = l.duration {
                s.millis(d);
            }
            match l.hold {
                Some(Hold::Stay) => s.option("hold", "stay"),
                Some(Hold::Return(m)) => s.option("hold", &m.0.to_string()),
                None => {}
            }
        }
        Action::Center { duration } => {
            let word = if s.chance(0.3) { "centre" } else { "center" };
            s.word(word);
            if let Some(d) = duration {
                s.millis(d);
            }
        }
        Action::Idle(on) => {
            s.word("idle");
            s.word(if on { "on" } else { "off" });
        }
        Action::IdleAmp(p) => {
            s.word("idle");
            s.word("amp");
            s.number(i64::from(p.get()));
        }
    }
}
