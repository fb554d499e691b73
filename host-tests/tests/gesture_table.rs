//! Every row of the gesture table works everywhere: the console parses its
//! word and lists it in `help`, the head plays it on its axis alone, the
//! built-in defaults and the settings record carry its defaults. Each test
//! runs over `GestureKind::ALL`, so a new row is tested without a word
//! added here.

use host_tests::behaviour::{default_params, frame, gesture};
use host_tests::console::head::{SimFrames, service, shared};
use idle_head_core::behaviour::{Applied, BehaviourConfig, Mixer};
use idle_head_core::command::{Action, Command, GestureKind, GestureRequest, Percent};
use idle_head_core::console::{HELP, Session, parse};
use idle_head_core::gestures::{MAX_CYCLES, Shape};
use idle_head_core::settings::{FieldReport, Record, Settings};
use idle_head_core::{Angle, Axis};

/// `line` parsed as a gesture request.
fn request(line: &str) -> GestureRequest {
    match parse(line.as_bytes()) {
        Ok(Command::Act(Action::Gesture(request))) => request,
        other => panic!("`{line}`: {other:?}"),
    }
}

#[test]
fn the_console_parses_every_gesture_by_its_word() {
    for kind in GestureKind::ALL {
        let name = kind.name();
        assert_eq!(request(name), GestureRequest::new(kind));
        assert_eq!(request(&name.to_uppercase()).kind, kind);
        let full = request(&format!("{name} -1500 900 intensity=30"));
        assert_eq!(full.amplitude, Some(Angle::from_millidegrees(-1500)));
        assert_eq!(full.intensity, Percent::new(30));
        // `cycles=` where the gesture may have more than one.
        let line = format!("{name} cycles=2");
        let cycles = parse(line.as_bytes());
        if kind.row().max_cycles > 1 {
            assert_eq!(request(&line).cycles, Some(2));
        } else {
            let err = cycles.unwrap_err();
            assert_eq!(
                err.describe(line.as_bytes()).to_string(),
                "`cycles=2`: unknown option (allowed: intensity)",
                "{name}"
            );
        }
    }
}

#[test]
fn help_lists_every_gesture() {
    let words: Vec<&str> = HELP.split_whitespace().collect();
    for kind in GestureKind::ALL {
        assert!(words.contains(&kind.name()), "{HELP}");
    }
}

#[test]
fn the_table_is_consistent() {
    for (i, kind) in GestureKind::ALL.into_iter().enumerate() {
        let row = kind.row();
        assert_eq!((row.kind, kind.index()), (kind, i));
        assert_eq!(GestureKind::from_name(row.name.as_bytes()), Some(kind));
        assert!((1..=MAX_CYCLES).contains(&row.max_cycles));
        assert!(row.shape.has_cycles() || row.max_cycles == 1, "{kind:?}");
        assert_eq!(BehaviourConfig::DEFAULT.defaults(kind), &row.defaults);
        assert!(row.fields.cycles.starts_with(row.name));
    }
    assert_eq!(GestureKind::from_name(b"wave"), None);
}

#[test]
fn the_head_plays_every_gesture_on_its_axis_alone() {
    for kind in GestureKind::ALL {
        let mut mixer = Mixer::new(default_params());
        let Ok(Applied::Gesture(plan)) = mixer.apply(&gesture(kind, None, None, None)) else {
            panic!("{kind:?} at its defaults")
        };
        let defaults = kind.row().defaults;
        let cycles = if kind.row().max_cycles == 1 {
            1
        } else {
            defaults.cycles
        };
        assert_eq!((plan.kind, plan.cycles), (kind, cycles));
        assert_eq!(plan.intensity, defaults.intensity);
        // The frames (of 20 ms) that start before its end.
        let frames = u64::from(plan.duration.0.div_ceil(20));
        let mut peak = 0;
        for k in 0..frames + 3 {
            let offsets = mixer.frame(frame(k), [Angle::ZERO; 3]);
            for axis in Axis::ALL {
                let value = offsets[axis.index()].millidegrees();
                if axis == kind.axis() {
                    peak = peak.max(value.abs());
                } else {
                    assert_eq!(value, 0, "{kind:?} moves {axis:?} at frame {k}");
                }
            }
            if k >= frames {
                assert_eq!(offsets, [Angle::ZERO; 3], "{kind:?} after its end");
            }
        }
        // A dip reaches its first peak; a swing nearly (a sine sampled at
        // frames); a lean holds it.
        let least = match kind.shape() {
            Shape::Dip | Shape::Lean => plan.amplitude.millidegrees().abs() * 99 / 100,
            Shape::Swing => plan.amplitude.millidegrees().abs() * 9 / 10,
        };
        assert!(peak >= least, "{kind:?}: peak {peak} m° of {plan:?}");
    }
}

#[test]
fn the_console_head_plays_every_gesture() {
    let (queue, link) = shared();
    let mut frames = SimFrames::new();
    let mut handler = service(queue, link);
    let mut session = Session::<96, 160>::new();
    for kind in GestureKind::ALL {
        session.feed(kind.name().as_bytes(), &mut handler, |_| {
            panic!("a reply before the line end")
        });
        assert_eq!(
            session.push(b'\n', &mut handler),
            None,
            "{kind:?}: it waits"
        );
        // The reply once the frame task took it: what it started.
        let reply = frames.finish(&mut session, queue, link, 0).unwrap();
        let reply = String::from_utf8_lossy(reply);
        assert!(
            reply.starts_with(&format!("ok {} amp_mdeg=", kind.name())),
            "{kind:?}: {reply}"
        );
        assert!(
            matches!(frames.last_applied, Some(Applied::Gesture(plan)) if plan.kind == kind),
            "{kind:?}: {:?}",
            frames.last_applied
        );
        for _ in 0..200 {
            frames.frame(queue, link);
        }
    }
    assert_eq!((frames.refused, frames.violations), (0, 0));
}

#[test]
fn the_settings_record_keeps_every_gestures_defaults() {
    let mut settings = Settings::DEFAULT;
    for (i, kind) in GestureKind::ALL.into_iter().enumerate() {
        let d = settings.behaviour.defaults_mut(kind);
        d.intensity = Percent::new(20 + i as u8).unwrap();
        d.amplitude = Angle::from_millidegrees(d.amplitude.millidegrees() - 100 - i as i32);
    }
    let mut buf = [0; 512];
    let n = settings.encode(&mut buf).unwrap();
    let mut report = FieldReport::default();
    assert_eq!(
        Settings::decode(Settings::VERSION, &buf[..n], &mut report),
        Ok(settings)
    );
    // Every gesture's block is in the record, each of its fields read back.
    assert!(report.is_clean(), "{report:?}");
    for kind in GestureKind::ALL {
        let first = kind.row().settings;
        for id in first..first + idle_head_core::gestures::SETTINGS_IDS {
            let field = idle_head_core::settings::field(id).expect("a field of the table");
            assert!(field.name.starts_with(kind.name()), "{}", field.name);
        }
    }
}
