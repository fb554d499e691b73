//! Every setting the console changes is answered back by the console: the
//! built-in values on a fresh head, each value as set, the built-in ones
//! after `defaults` and the saved ones after `load`. A program (the panel)
//! reads the head's settings from these answers alone.
//!
//! | setting | changed by | read back by |
//! |---|---|---|
//! | a servo's calibration | `servo <axis> <field> …` | `servo <axis>` |
//! | the servo rate | `servo rate <hz>` | `servo rate` |
//! | the rest timer, pose, relax | `rest after|pose|relax …` | `rest after`, `rest pose` or `rest relax` alone |
//! | the look's duck | `look duck <p>` | `look duck` |
//! | the idle amplitude (and idle on or off) | `idle amp <p>` (`idle on|off`) | `idle` |
//! | the seeds | `seed …` | `seed` |
//! | a trigger input | `input <n> …` | `input <n>` |
//! | DMX on or off, its address | `dmx on|off`, `dmx address` | `dmx` |
//! | the radar on or off | `radar on|off` | `radar` |
//! | the tracking | `track on|off|height|mount|prefer` | `track` |

use host_tests::console::talk::SimConsole;

/// Each setting's read-back, and its answer on the built-in settings (as
/// `docs/user/protocol.md` gives the defaults).
const BUILT_IN: &[(&str, &str)] = &[
    (
        "servo yaw",
        "ok yaw neutral=1500 per-degree=11111 direction=normal min=1000 max=2000 limits=-23000,32000",
    ),
    ("servo rate", "ok servo rate=50 period_us=20000"),
    ("rest after", "ok rest after=120 pose=8000,0,0 relax=off"),
    ("look duck", "ok look duck=80"),
    ("idle", "ok idle=on amp=100"),
    ("seed", "ok seed=board:none"),
    ("input 2", "ok input 2 off"),
    (
        "dmx",
        "ok dmx=lost address=1 good=0 short=0 long=0 start_code=0 garbled=0",
    ),
    ("radar", "ok radar=off frames=0 bad=0 targets=0"),
    ("track", "ok track=on height=300 mount=0 prefer=nearest"),
];

/// Each setting changed away from its built-in value, its read-back and
/// the answer then.
const CHANGED: &[(&str, &str, &str)] = &[
    (
        "servo yaw neutral 1520",
        "servo yaw",
        "ok yaw neutral=1520 per-degree=11111 direction=normal min=1000 max=2000 limits=-23000,32000",
    ),
    (
        "servo rate 200",
        "servo rate",
        "ok servo rate=200 period_us=5000",
    ),
    (
        "rest after 300",
        "rest pose",
        "ok rest after=300 pose=8000,0,0 relax=off",
    ),
    (
        "rest pose -10000 2000 5000",
        "rest relax",
        "ok rest after=300 pose=-10000,2000,5000 relax=off",
    ),
    (
        "rest relax on",
        "rest after",
        "ok rest after=300 pose=-10000,2000,5000 relax=on",
    ),
    ("look duck 35", "look duck", "ok look duck=35"),
    ("idle amp 40", "idle", "ok idle=on amp=40"),
    ("seed 42", "seed", "ok seed=42"),
    (
        "input 2 button nod 5000 cycles=3",
        "input 2",
        "ok input 2 level=high active=0 button nod 5000 cycles=3",
    ),
    (
        "dmx address 17",
        "dmx",
        "ok dmx=lost address=17 good=0 short=0 long=0 start_code=0 garbled=0",
    ),
    (
        "dmx off",
        "dmx",
        "ok dmx=off address=17 good=0 short=0 long=0 start_code=0 garbled=0",
    ),
    ("radar on", "radar", "ok radar=on frames=0 bad=0 targets=0"),
    (
        "track height -250",
        "track",
        "ok track=on height=-250 mount=0 prefer=nearest",
    ),
    (
        "track mount 15000",
        "track",
        "ok track=on height=-250 mount=15000 prefer=nearest",
    ),
    (
        "track prefer newest",
        "track",
        "ok track=on height=-250 mount=15000 prefer=newest",
    ),
    (
        "track off",
        "track",
        "ok track=off height=-250 mount=15000 prefer=newest",
    ),
];

fn read_all(c: &mut SimConsole) -> Vec<String> {
    BUILT_IN.iter().map(|(line, _)| c.ask(line)).collect()
}

#[test]
fn a_fresh_head_answers_its_built_in_settings() {
    let mut c = SimConsole::new();
    for (line, want) in BUILT_IN {
        assert_eq!(c.ask(line), *want, "`{line}`");
    }
}

#[test]
fn every_setting_reads_back_as_set_after_defaults_and_after_load() {
    let mut c = SimConsole::new();
    for (set, read, want) in CHANGED {
        let reply = c.ask(set);
        assert!(reply.starts_with("ok"), "`{set}`: {reply}");
        assert_eq!(c.ask(read), *want, "`{read}` after `{set}`");
    }
    assert!(c.ask("status").contains(" settings=changed "));
    let set = read_all(&mut c);
    // Each read-back answers something else than on the built-in settings.
    for ((line, built_in), now) in BUILT_IN.iter().zip(&set) {
        assert_ne!(now, built_in, "`{line}` did not change");
    }
    assert_eq!(c.ask("save"), "ok");
    assert_eq!(c.ask("defaults"), "ok");
    c.play(2);
    for (line, want) in BUILT_IN {
        assert_eq!(c.ask(line), *want, "`{line}` after `defaults`");
    }
    assert_eq!(c.ask("load"), "ok");
    c.play(2);
    assert_eq!(read_all(&mut c), set, "after `load`");
    assert!(c.ask("status").contains(" settings=flash "));
}

#[test]
fn a_rest_pose_past_the_limits_reads_back_as_set_with_where_the_head_rests() {
    let mut c = SimConsole::new();
    assert_eq!(
        c.ask("rest pose -30000 0 0"),
        "ok clamped pitch=-12000 roll=0 yaw=0"
    );
    assert_eq!(
        c.ask("rest relax"),
        "ok rest after=120 pose=-30000,0,0 relax=off clamped=-12000,0,0"
    );
    assert_eq!(c.ask("rest after never"), "ok");
    assert_eq!(
        c.ask("rest after"),
        "ok rest after=never pose=-30000,0,0 relax=off clamped=-12000,0,0"
    );
}

#[test]
fn idle_answers_what_the_head_does_and_its_amplitude_is_kept() {
    let mut c = SimConsole::new();
    assert_eq!(c.ask("idle off"), "ok idle=0");
    assert_eq!(c.ask("idle"), "ok idle=off amp=100");
    assert!(
        c.ask("status").contains(" settings=defaults "),
        "on and off is not a setting"
    );
    assert_eq!(c.ask("idle amp 40"), "ok idle=0");
    assert_eq!(c.ask("idle"), "ok idle=off amp=40");
    assert_eq!(c.ask("idle on"), "ok idle=40");
    assert_eq!(c.ask("idle"), "ok idle=on amp=40");
    // The amplitude is a setting: saved, and put back by `load`.
    assert!(c.ask("status").contains(" settings=changed "));
    assert_eq!(c.ask("save"), "ok");
    assert_eq!(c.ask("idle amp 70"), "ok idle=70");
    assert_eq!(c.ask("load"), "ok");
    c.play(2);
    assert_eq!(c.ask("idle"), "ok idle=on amp=40");
    assert_eq!(c.ask("defaults"), "ok");
    c.play(2);
    assert_eq!(c.ask("idle"), "ok idle=on amp=100");
}

#[test]
fn idle_before_the_first_frame_answers_the_settings() {
    let (queue, link) = host_tests::console::head::shared();
    let mut service = host_tests::console::head::service(queue, link);
    let mut out = [0; 160];
    let reply = match idle_head_core::console::respond(Ok(b"idle"), &mut service, &mut out) {
        idle_head_core::console::Response::Now(reply) => reply.to_vec(),
        idle_head_core::console::Response::Later(_) => panic!("`idle` waits"),
    };
    assert_eq!(reply, b"ok idle=on amp=100\r\n");
}
