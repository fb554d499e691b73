//! The console parser: every command, every kind of error, and the reason
//! text a user reads.

use idle_head_core::command::{
    Action, Command, GestureKind, GestureRequest, Hold, LookRequest, Percent, SeedChoice,
    ServoSetting,
};
use idle_head_core::console::{ParseErrorKind, Span, parse};
use idle_head_core::servo::{Direction, NanosPerDegree};
use idle_head_core::{Angle, AngleRange, Axis, Microseconds, Millis};

fn ok(line: &str) -> Command {
    parse(line.as_bytes()).unwrap_or_else(|e| {
        panic!("`{line}`: {}", e.describe(line.as_bytes()));
    })
}

fn reason(line: &str) -> String {
    match parse(line.as_bytes()) {
        Ok(c) => panic!("`{line}` parsed as {c:?}"),
        Err(e) => format!("{} {}", e.code(), e.describe(line.as_bytes())),
    }
}

fn gesture(kind: GestureKind) -> GestureRequest {
    GestureRequest::new(kind)
}

#[test]
fn words_without_arguments() {
    assert_eq!(ok("help"), Command::Help);
    assert_eq!(ok("status"), Command::Status);
    assert_eq!(ok("save"), Command::Save);
    assert_eq!(ok("load"), Command::Load);
    assert_eq!(ok("defaults"), Command::Defaults);
    assert_eq!(ok("stop"), Command::Act(Action::Stop));
    // Case and blanks do not matter.
    assert_eq!(ok("  STATUS\t "), Command::Status);
}

#[test]
fn gestures_with_defaults_and_options() {
    assert_eq!(
        ok("nod"),
        Command::Act(Action::Gesture(gesture(GestureKind::Nod)))
    );
    let mut shake = gesture(GestureKind::Shake);
    shake.amplitude = Some(Angle::from_millidegrees(8000));
    shake.duration = Some(Millis(1200));
    shake.cycles = Some(4);
    shake.intensity = Some(Percent::new(70).unwrap());
    assert_eq!(
        ok("shake 8000 1200 intensity=70 cycles=4"),
        Command::Act(Action::Gesture(shake))
    );
    let mut tilt = gesture(GestureKind::Tilt);
    tilt.amplitude = Some(Angle::from_millidegrees(-7000));
    assert_eq!(ok("tilt -7000"), Command::Act(Action::Gesture(tilt)));
    // Options alone, without the positional numbers.
    let mut nod = gesture(GestureKind::Nod);
    nod.cycles = Some(2);
    assert_eq!(ok("Nod cycles=2"), Command::Act(Action::Gesture(nod)));
}

#[test]
fn look_center_idle_seed() {
    assert_eq!(
        ok("look 5000 -12000"),
        Command::Act(Action::Look(LookRequest {
            pitch: Angle::from_degrees(5),
            yaw: Angle::from_degrees(-12),
            duration: None,
            hold: None,
        }))
    );
    assert_eq!(
        ok("look 0 9000 600 hold=stay"),
        Command::Act(Action::Look(LookRequest {
            pitch: Angle::ZERO,
            yaw: Angle::from_degrees(9),
            duration: Some(Millis(600)),
            hold: Some(Hold::Stay),
        }))
    );
    assert_eq!(
        ok("look 0 0 hold=2500"),
        Command::Act(Action::Look(LookRequest {
            pitch: Angle::ZERO,
            yaw: Angle::ZERO,
            duration: None,
            hold: Some(Hold::Return(Millis(2500))),
        }))
    );
    assert_eq!(
        ok("center"),
        Command::Act(Action::Center { duration: None })
    );
    assert_eq!(
        ok("centre 400"),
        Command::Act(Action::Center {
            duration: Some(Millis(400))
        })
    );
    assert_eq!(ok("idle on"), Command::Act(Action::Idle(true)));
    assert_eq!(ok("idle OFF"), Command::Act(Action::Idle(false)));
    assert_eq!(
        ok("idle amp 35"),
        Command::Act(Action::IdleAmp(Percent::new(35).unwrap()))
    );
    assert_eq!(
        ok("seed 4294967295"),
        Command::Seed(SeedChoice::Value(u32::MAX))
    );
    assert_eq!(ok("seed random"), Command::Seed(SeedChoice::Random));
}

/// The settings that have no word of their own to show them: `rest
/// after|pose|relax` alone, `look duck` alone and `idle` alone ask; with a
/// value they set (`rest` and `look` stay motions).
#[test]
fn settings_shown_by_their_words_alone() {
    use idle_head_core::command::{RestAfter, RestSetting};
    for line in ["rest after", "REST pose", "rest\trelax "] {
        assert_eq!(ok(line), Command::Rest(None), "`{line}`");
    }
    assert_eq!(ok("look duck"), Command::LookDuck(None));
    assert_eq!(ok("idle"), Command::IdleQuery);
    assert_eq!(ok("  Idle "), Command::IdleQuery);
    assert_eq!(
        ok("rest after never"),
        Command::Rest(Some(RestSetting::After(RestAfter::Never)))
    );
    assert_eq!(
        ok("rest relax on"),
        Command::Rest(Some(RestSetting::Relax(true)))
    );
    assert_eq!(
        ok("look duck 70"),
        Command::LookDuck(Some(Percent::new(70).unwrap()))
    );
    assert_eq!(ok("rest"), Command::Act(Action::Rest));
    assert_eq!(ok("idle off"), Command::Act(Action::Idle(false)));
}

#[test]
fn servo_fields() {
    let servo = |axis, setting| Command::Servo {
        axis,
        setting: Some(setting),
    };
    assert_eq!(
        ok("servo pitch"),
        Command::Servo {
            axis: Axis::Pitch,
            setting: None
        }
    );
    assert_eq!(
        ok("servo roll neutral 1520"),
        servo(Axis::Roll, ServoSetting::Neutral(Microseconds(1520)))
    );
    assert_eq!(
        ok("servo yaw per-degree 10500"),
        servo(Axis::Yaw, ServoSetting::PerDegree(NanosPerDegree(10_500)))
    );
    assert_eq!(
        ok("servo yaw direction reversed"),
        servo(Axis::Yaw, ServoSetting::Direction(Direction::Reversed))
    );
    assert_eq!(
        ok("servo pitch min 950"),
        servo(Axis::Pitch, ServoSetting::MinPulse(Microseconds(950)))
    );
    assert_eq!(
        ok("servo pitch max 2050"),
        servo(Axis::Pitch, ServoSetting::MaxPulse(Microseconds(2050)))
    );
    assert_eq!(
        ok("servo roll limits -10000 15000"),
        servo(
            Axis::Roll,
            ServoSetting::Limits(AngleRange {
                min: Angle::from_degrees(-10),
                max: Angle::from_degrees(15),
            })
        )
    );
}

#[test]
fn errors_name_the_word_and_the_rule() {
    let cases = [
        ("", "syntax empty line (try `help`)"),
        ("   ", "syntax empty line (try `help`)"),
        ("nodd", "syntax unknown command `nodd` (try `help`)"),
        ("nod 6000 900 5", "syntax `5`: unexpected"),
        (
            "nod 6k",
            "syntax `6k`: amplitude in mdeg must be a whole number",
        ),
        (
            "nod 6000 0",
            "range `0`: duration in ms must be in 1..=4294967295",
        ),
        ("nod cycles=0", "range `0`: cycles must be in 1..=255"),
        (
            "tilt 5000 cycles=2",
            "syntax `cycles=2`: unknown option (allowed: intensity)",
        ),
        (
            "nod intensity=5 intensity=6",
            "syntax `intensity=6`: option given twice",
        ),
        (
            "nod intensity=101",
            "range `101`: percentage must be in 0..=100",
        ),
        ("look 5000", "syntax missing yaw in mdeg"),
        (
            "look 1 2 hold=soon",
            "syntax `soon`: hold in ms must be a whole number",
        ),
        ("input 2 button idle", "syntax missing `on`, `off` or `amp`"),
        ("rest pose 1000", "syntax missing roll in mdeg"),
        ("rest after 0", "range `0`: seconds must be in 1..=86400"),
        (
            "look duck 101",
            "range `101`: percentage must be in 0..=100",
        ),
        ("look duck 50 now", "syntax `now`: unexpected"),
        ("idle now", "syntax `now`: expected `on`, `off` or `amp`"),
        (
            "idle maybe",
            "syntax `maybe`: expected `on`, `off` or `amp`",
        ),
        ("seed -1", "range `-1`: seed must be in 0..=4294967295"),
        (
            "seed 4294967296",
            "range `4294967296`: seed must be in 0..=4294967295",
        ),
        (
            "servo neck",
            "syntax `neck`: expected `pitch`, `roll`, `yaw` or `rate`",
        ),
        (
            "servo yaw trim 5",
            "syntax `trim`: expected `neutral`, `per-degree`, `direction`, `min`, `max` or `limits`",
        ),
        (
            "servo yaw limits -5000",
            "syntax missing upper limit in mdeg",
        ),
        ("status now", "syntax `now`: unexpected"),
        (
            "nod 99999999999999999999",
            "range `99999999999999999999`: amplitude in mdeg must be in -2147483647..=2147483647",
        ),
        (
            "nod \u{e9}",
            "syntax `\\xc3\\xa9`: amplitude in mdeg must be a whole number",
        ),
    ];
    for (line, want) in cases {
        assert_eq!(reason(line), want, "line `{line}`");
    }
}

/// However many digits a number has, it is a number: one too long for its
/// field is out of range, as a shorter one past the field's limit is.
#[test]
fn an_over_long_number_is_out_of_range_not_a_syntax_error() {
    for digits in [10, 11, 19, 20, 40, 200] {
        let number = "9".repeat(digits);
        for (line, what) in [
            (format!("look 0 {number}"), "yaw in mdeg"),
            (format!("look 0 -{number}"), "yaw in mdeg"),
            (format!("seed {number}"), "seed"),
            (format!("seed +{number}"), "seed"),
            (format!("nod 5000 800 intensity={number}"), "percentage"),
        ] {
            let err = parse(line.as_bytes()).unwrap_err();
            assert!(
                matches!(err.kind, ParseErrorKind::OutOfRange { what: w, .. } if w == what),
                "`{line}`: {err:?}"
            );
            assert_eq!(err.code(), "range", "`{line}`");
        }
    }
    // Digits and something else are still no number.
    let err = parse(format!("seed {}x", "9".repeat(40)).as_bytes()).unwrap_err();
    assert_eq!(err.kind, ParseErrorKind::NotANumber("seed"));
}

#[test]
fn spans_point_at_the_word() {
    let err = parse(b"look 10 x").unwrap_err();
    assert_eq!(err.kind, ParseErrorKind::NotANumber("yaw in mdeg"));
    assert_eq!(err.at, Span { start: 8, end: 9 });
    let err = parse(b"look 10").unwrap_err();
    assert_eq!(err.at, Span { start: 7, end: 7 });
    // Bytes that are no text at all are just unknown words.
    let err = parse(&[0xff, 0xfe]).unwrap_err();
    assert_eq!(err.kind, ParseErrorKind::UnknownCommand);
}
