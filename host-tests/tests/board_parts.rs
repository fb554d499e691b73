//! A board states the parts it has, and the console answers for them: on a
//! board with servos and a console only, every command for a missing part
//! gets `err unavailable …`, never a made-up answer; the trigger inputs
//! are the board's (their count and numbers), and a settings record saved
//! on a board with four inputs loads on one with two.

use host_tests::console::REPLY;
use host_tests::console::head::{pico_parts, service, shared};
use idle_head_core::behaviour::ShowLink;
use idle_head_core::console::{BoardParts, ConsoleService, ErrorCode, Handler, respond};
use idle_head_core::input::InputIds;
use idle_head_core::settings::{RamStorage, SettingsStorage};

/// The reply to `line`, which must come at once (no motion).
fn say<H: Handler>(svc: &mut H, line: &str) -> String {
    let mut out = [0; REPLY];
    let reply = respond(Ok(line.as_bytes()), svc, &mut out)
        .now()
        .expect("an immediate reply")
        .to_vec();
    String::from_utf8(reply).unwrap().trim_end().to_owned()
}

/// A board with inputs numbered `ids`, no DMX, no radar, a RAM store.
fn board_with_inputs(ids: &[u8]) -> ConsoleService<'static, RamStorage> {
    let (queue, link) = shared();
    ConsoleService::with_defaults(queue, link, RamStorage::new())
        .with_show(Box::leak(Box::new(ShowLink::new())))
        .with_parts(BoardParts {
            inputs: InputIds::new(ids).unwrap(),
            ..BoardParts::NONE
        })
}

#[test]
fn a_board_with_servos_and_usb_only_says_what_it_lacks() {
    let (queue, link) = shared();
    // As `idle_head_rp::start` makes it for `examples/minimal.rs`: no store
    // (`None`), no inputs, DMX or radar.
    let mut svc: ConsoleService<'_, Option<RamStorage>> =
        ConsoleService::with_defaults(queue, link, None)
            .with_show(Box::leak(Box::new(ShowLink::new())))
            .with_parts(BoardParts::NONE);
    let status = say(&mut svc, "status");
    assert!(status.starts_with("ok mode="), "{status}");
    for absent in [" inputs=", " dmx="] {
        assert!(!status.contains(absent), "{status}");
    }
    assert!(status.contains(" settings=defaults "), "{status}");
    let refused = [
        ("save", "save: this board has no settings store"),
        ("load", "load: this board has no settings store"),
        ("dmx", "this board has no DMX receiver"),
        ("radar", "this board has no radar"),
        ("input 2", "this board has no trigger inputs"),
        ("input 2 button nod", "this board has no trigger inputs"),
    ];
    for (line, why) in refused {
        assert_eq!(
            say(&mut svc, line),
            format!("err unavailable {why}"),
            "{line}"
        );
    }
    // Settings are settings on any board: kept, shown back (and saved on a
    // board that can).
    assert_eq!(say(&mut svc, "dmx on"), "ok");
    assert_eq!(say(&mut svc, "radar on"), "ok");
    assert_eq!(
        say(&mut svc, "track"),
        "ok track=on height=300 mount=0 prefer=nearest"
    );
    assert_eq!(say(&mut svc, "seed"), "ok seed=board:none");
    assert!(svc.settings().dmx.on && svc.settings().track.radar);
}

#[test]
fn unavailable_is_a_protocol_code() {
    assert!(ErrorCode::ALL.contains(&ErrorCode::Unavailable));
    assert_eq!(ErrorCode::Unavailable.as_str(), "unavailable");
}

#[test]
fn the_inputs_are_the_boards_numbers_and_no_others() {
    let mut svc = board_with_inputs(&[7, 9]);
    assert_eq!(say(&mut svc, "input 7 button nod"), "ok");
    assert_eq!(say(&mut svc, "input 9 presence"), "ok");
    assert_eq!(
        say(&mut svc, "input 9"),
        "ok input 9 level=low active=0 presence"
    );
    for other in ["2", "5", "8", "0", "255"] {
        assert_eq!(
            say(&mut svc, &format!("input {other}")),
            format!("err range this board has no input {other}: its inputs are 7, 9")
        );
    }
    // Past a byte: the parser's range, as for any field.
    assert!(say(&mut svc, "input 256").starts_with("err range "));
    let status = say(&mut svc, "status");
    assert!(
        status.contains(" inputs=b0,p0 "),
        "two inputs, in order: {status}"
    );
    // The Pico's four, GP2 to GP5, as before.
    let (queue, link) = shared();
    let mut pico = service(queue, link);
    assert_eq!(pico_parts().inputs.as_slice(), [2, 3, 4, 5]);
    assert!(say(&mut pico, "status").contains(" inputs=-,-,-,- "));
    assert_eq!(say(&mut pico, "input 5"), "ok input 5 off");
    assert_eq!(
        say(&mut pico, "input 6"),
        "err range this board has no input 6: its inputs are 2, 3, 4, 5"
    );
}

#[test]
fn settings_saved_with_four_inputs_load_on_a_board_with_two_and_keep_the_others() {
    let (queue, link) = shared();
    let mut pico = service(queue, link);
    for line in [
        "input 2 button nod",
        "input 3 presence 20000",
        "input 5 button shake",
        "save",
    ] {
        assert_eq!(say(&mut pico, line), "ok", "{line}");
    }
    let saved = pico.storage_mut().raw().to_vec();
    let mut two = board_with_inputs(&[7, 9]);
    two.storage_mut().set_raw(&saved).unwrap();
    assert_eq!(say(&mut two, "load"), "ok");
    // Slot by slot: the first two roles are this board's inputs.
    assert_eq!(
        say(&mut two, "input 7"),
        "ok input 7 level=low active=0 button nod"
    );
    assert_eq!(
        say(&mut two, "input 9"),
        "ok input 9 level=low active=0 presence 20000"
    );
    // Saved again from here, the roles of the slots it lacks are kept.
    assert_eq!(say(&mut two, "save"), "ok");
    let back = two.storage_mut().load().unwrap();
    assert_eq!(back.inputs, pico.settings().inputs);
    assert_eq!(say(&mut pico, "load"), "ok");
}
