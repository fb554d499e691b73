//! Bottango's driver protocol on a console port: the session in
//! `docs/user/show.md` replayed through a port's `DualSession` and the
//! firmware's console service on a simulated head, every reply line as the
//! document has it, and what each command did to the curves the frame task
//! plays.

use host_tests::console::head::{service, shared};
use idle_head_core::Axis;
use idle_head_core::bottango::{Curves, Sample};
use idle_head_core::console::{DualSession, unanswered};

/// The `> line` / `< reply` pairs of the document's session.
fn transcript() -> Vec<(String, Vec<String>)> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/user/show.md");
    let doc = std::fs::read_to_string(path).expect("docs/user/show.md");
    let block = doc
        .split("### A session")
        .nth(1)
        .and_then(|rest| rest.split("```text\n").nth(1))
        .and_then(|rest| rest.split("```").next())
        .expect("a ```text block under `### A session`");
    let mut pairs: Vec<(String, Vec<String>)> = Vec::new();
    for line in block.lines() {
        if let Some(sent) = line.strip_prefix("> ") {
            pairs.push((sent.to_owned(), Vec::new()));
        } else if let Some(reply) = line.strip_prefix('<') {
            let reply = reply.strip_prefix(' ').unwrap_or(reply);
            pairs
                .last_mut()
                .expect("a reply after a line")
                .1
                .push(reply.to_owned());
        }
    }
    pairs
}

/// The reply lines of `bytes`, without their line ends.
fn lines(bytes: &[u8]) -> Vec<String> {
    String::from_utf8(bytes.to_vec())
        .unwrap()
        .split_terminator('\n')
        .map(|l| l.trim_end_matches('\r').to_owned())
        .collect()
}

struct Port {
    session: DualSession<'static>,
    handler: idle_head_core::console::ConsoleService<'static, idle_head_core::settings::RamStorage>,
    curves: &'static Curves,
}

impl Port {
    fn new() -> Self {
        let (queue, link) = shared();
        let curves: &'static Curves = Box::leak(Box::new(Curves::new()));
        Self {
            session: DualSession::new(Some(curves)),
            handler: service(queue, link),
            curves,
        }
    }

    /// Sends `bytes`; every reply line, in order.
    fn send(&mut self, bytes: &[u8]) -> Vec<String> {
        let mut out = Vec::new();
        for &byte in bytes {
            if let Some(reply) = self.session.push(byte, &mut self.handler) {
                out.extend(lines(reply));
            }
        }
        out
    }
}

#[test]
fn the_session_in_the_documentation_holds() {
    let mut port = Port::new();
    // The frame task's clock stands at 5 s: the sync marks it.
    port.curves.sample(5000);
    let mut after = Vec::new();
    for (sent, want) in transcript() {
        let got = port.send(format!("{sent}\n").as_bytes());
        assert_eq!(got, want, "`{sent}`");
        after.push((sent, port.session.bottango(), port.curves.sample(5000)));
    }
    assert!(after.len() >= 20, "{} lines", after.len());
    let state = |prefix: &str| {
        after
            .iter()
            .find(|(sent, ..)| sent.starts_with(prefix))
            .map(|(_, bottango, sample)| (*bottango, *sample))
            .unwrap_or_else(|| panic!("no `{prefix}` in the session"))
    };
    // The handshake switched the port; STOP switched it back.
    assert!(state("hRQ").0);
    assert_eq!(state("STOP"), (false, None));
    assert!(!port.session.bottango());
    // Both curves registered, neither started at the sync.
    let (_, Some(queued)) = state("sC,pitch") else {
        panic!("no session")
    };
    assert_eq!((queued.axes, queued.playing), (0, true));
    // Deregistered: nothing left.
    assert_eq!(state("xE").1, Some(Sample::default()));
}

#[test]
fn the_curves_play_from_the_sync_on() {
    let mut port = Port::new();
    port.curves.sample(5000);
    for (sent, _) in transcript()
        .into_iter()
        .take_while(|(sent, _)| !sent.starts_with("sCI"))
    {
        port.send(format!("{sent}\n").as_bytes());
    }
    // The sync was at 5 s; the curves start 100 ms later and take 2 s.
    let at = |ms| port.curves.sample(ms).unwrap();
    assert_eq!(at(5050).axes, 0);
    let start = at(5100);
    assert_eq!(start.axes, 0b101);
    assert_eq!(
        (
            start.angles[Axis::Yaw.index()],
            start.angles[Axis::Pitch.index()]
        ),
        (0, 0)
    );
    let middle = at(6100);
    assert!(middle.playing);
    assert!(
        (9000..11_000).contains(&middle.angles[Axis::Yaw.index()]),
        "{middle:?}"
    );
    let end = at(7100);
    assert_eq!(end.angles[Axis::Yaw.index()], 20_000);
    assert_eq!(end.angles[Axis::Pitch.index()], 5_000);
    let past = at(9000);
    assert!(!past.playing);
    assert_eq!(past.angles, end.angles);
}

#[test]
fn a_bad_handshake_stays_in_the_console() {
    let mut port = Port::new();
    let got = port.send(b"hRQ,144,h463\n");
    assert!(got[0].starts_with("err syntax unknown command"), "{got:?}");
    assert!(!port.session.bottango());
    assert_eq!(port.curves.sample(0), None);
}

#[test]
fn a_line_that_stops_arriving_times_out() {
    let mut port = Port::new();
    port.send(b"hRQ,7,h366\n");
    assert!(port.session.bottango());
    assert!(port.session.timeout().is_none(), "no line in progress");
    assert!(port.send(b"sC,yaw,1").is_empty());
    assert!(port.session.in_progress());
    assert_eq!(
        port.session.timeout().map(lines),
        Some(vec!["TIMEOUT".to_owned()])
    );
    // The rest of the line is a line of its own: its hash fails.
    assert_eq!(port.send(b"00,h5\n"), ["HASH_FAIL"]);
    assert_eq!(port.send(b"xE,h189\n"), ["OK"]);
}

#[test]
fn the_port_going_away_ends_the_session() {
    let mut port = Port::new();
    port.send(b"hRQ,7,h366\nrMTR,roll,-14000,19000,3000,0,h1801\n");
    assert!(port.curves.active());
    port.session.reset();
    assert!(!port.session.bottango());
    assert_eq!(port.curves.sample(0), None);
    // A repeated handshake in a session gets no answer, as in Bottango's
    // own driver; a new one after the reset does.
    port.send(b"hRQ,7,h366\n");
    assert!(port.send(b"hRQ,8,h367\n").is_empty());
    assert!(port.session.bottango());
}

#[test]
fn a_console_reply_waits_on_a_dual_port_as_on_a_session() {
    let mut port = Port::new();
    assert!(port.send(b"nod\n").is_empty(), "queued: the reply waits");
    assert!(port.session.waiting().is_some());
    assert!(port.session.spare().is_empty(), "the reply holds it");
    assert!(port.send(b"status\n").is_empty(), "bytes not taken");
    let reply = port.session.finish(|r| unanswered(r, 500)).map(lines);
    assert_eq!(
        reply,
        Some(vec![
            "err state no frame took the command within 500 ms: the frames are not running"
                .to_owned()
        ])
    );
    assert_eq!(port.session.waiting(), None);
    assert_eq!(port.session.spare().len(), host_tests::console::REPLY);
    let status = port.send(b"status\n");
    assert!(status[0].starts_with("ok mode="), "{status:?}");
}
