//! What `docs/user/protocol.md` and `docs/user/show.md` say beside their
//! example exchanges (those are replayed by `doc_transcripts.rs`): a row
//! for every gesture, the telemetry line and its bandwidth, the DMX bands.

/// Every gesture of the table has its row in the document's table of
/// commands, with `cycles=` where the gesture may have more than one.
#[test]
fn the_protocol_document_lists_every_gesture() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/user/protocol.md");
    let doc = std::fs::read_to_string(path).expect("docs/user/protocol.md");
    for kind in idle_head_core::command::GestureKind::ALL {
        let options = if kind.row().max_cycles > 1 {
            "[cycles=N] [intensity=P]"
        } else {
            "[intensity=P]"
        };
        let row = format!("| `{} [amp] [ms] {options}` |", kind.name());
        assert!(
            doc.lines().any(|line| line.starts_with(&row)),
            "docs/user/protocol.md has no row `{row}`"
        );
    }
}

/// The telemetry example and the bandwidth figures in the document are
/// the firmware's: its line for that status, and the arithmetic on it.
#[test]
fn the_telemetry_figures_in_the_protocol_document_hold() {
    use idle_head_core::console::{HeadMode, HeadStatus, TELEMETRY_LINE, telemetry_line};
    use idle_head_core::{Angle, Microseconds, Timestamp};
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/user/protocol.md");
    let doc = std::fs::read_to_string(path).expect("docs/user/protocol.md");
    let status = HeadStatus {
        frame: 123_440 / 20,
        time: Timestamp(123_440_000),
        mode: HeadMode::Running,
        angles: [-1505, -119, -236].map(Angle::from_millidegrees),
        pulses: [1483, 1499, 1497].map(Microseconds),
        faults: [0; 3],
        disabled: [false; 3],
        track: None,
        idle: None,
    };
    let mut out = [0; TELEMETRY_LINE];
    let line = telemetry_line(&status, 0, &mut out);
    let text = std::str::from_utf8(line).unwrap();
    assert!(
        doc.contains(text.trim_end()),
        "the document's example line: {text}"
    );
    let bytes = line.len();
    // 50 lines a second, 10 bits a byte on the UART (8N1), 115200 baud.
    let per_second = bytes * 50;
    let percent = |n: usize| n * 50 * 10 * 100 / 115_200;
    let figures = [
        format!("about {bytes} bytes"),
        format!("{},{:03} bytes", per_second / 1000, per_second % 1000),
        format!(
            "{},{:03} bits a second",
            per_second * 10 / 1000,
            per_second * 10 % 1000
        ),
        format!("{} % of UART0", percent(bytes)),
        format!(
            "({TELEMETRY_LINE} bytes) would take {} %",
            percent(TELEMETRY_LINE)
        ),
    ];
    // With the radar on and two people: the second example line.
    let person = |x, y| {
        Some(idle_head_core::track::Person {
            x: idle_head_core::Millimetres(x),
            y: idle_head_core::Millimetres(y),
        })
    };
    let people = idle_head_core::track::Sighting {
        people: [person(500, 2000), person(-1200, 3400), None],
    };
    let radar = HeadStatus {
        track: Some(idle_head_core::track::TrackView {
            seen: people,
            who: Some(0),
            at: Some(Angle::from_millidegrees(-14_036)),
        }),
        ..status
    };
    let mut out = [0; TELEMETRY_LINE];
    let line = telemetry_line(&radar, 0, &mut out);
    let text = std::str::from_utf8(line).unwrap();
    assert!(
        doc.contains(text.trim_end()),
        "the document's radar example line: {text}"
    );
    let figures = figures.into_iter().chain([
        format!("two people (the second line) it takes {} bytes", line.len()),
        format!("{} %\nat 50 lines a second", percent(line.len())),
        format!(
            "At 20\nlines a second, as the panel asks for them, the longest takes {} %",
            TELEMETRY_LINE * 20 * 10 * 100 / 115_200
        ),
    ]);
    for figure in figures {
        assert!(
            doc.contains(&figure),
            "docs/user/protocol.md should say `{figure}`"
        );
    }
}

/// The show document's DMX personality gives every gesture of the table
/// its trigger band, as the core reads slot 8.
#[test]
fn the_show_document_gives_every_gesture_its_dmx_band() {
    use idle_head_core::dmx::Trigger;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/user/show.md");
    let doc = std::fs::read_to_string(path).expect("docs/user/show.md");
    let row = doc
        .lines()
        .find(|line| line.starts_with("| 8 | gesture trigger:"))
        .expect("the trigger slot's row");
    for kind in idle_head_core::command::GestureKind::ALL {
        let band = Trigger::band(kind);
        let text = format!("{}–{} {}", band.start(), band.end(), kind.name());
        assert!(row.contains(&text), "`{text}` missing from {row:?}");
    }
}
