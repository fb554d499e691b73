//! The exchanges in `docs/protocol.md` are what the console does: every
//! `> line` of an example, sent to a session whose handler answers `help`
//! with the help line and any other command with a bare `ok`, gets the
//! `< reply` written under it, byte for byte.

use idle_head::command::Command;
use idle_head::console::{HELP, Reply, Session};

#[test]
fn the_examples_in_the_protocol_document_hold() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/protocol.md");
    let doc = std::fs::read_to_string(path).expect("docs/protocol.md");
    let mut handler = |command: Command, reply: &mut Reply<'_>| {
        if command == Command::Help {
            std::fmt::Write::write_str(reply.ok(), HELP).unwrap();
        }
    };
    let mut session = Session::<96, 160>::new();
    let mut exchanges = 0;
    let mut lines = doc.lines().peekable();
    while let Some(line) = lines.next() {
        let Some(sent) = line.strip_prefix("> ") else {
            continue;
        };
        let want = lines
            .next()
            .and_then(|l| l.strip_prefix("< "))
            .unwrap_or_else(|| panic!("`> {sent}` has no `< ` reply under it"));
        let mut got = Vec::new();
        session.feed(format!("{sent}\r\n").as_bytes(), &mut handler, |r| {
            got.push(String::from_utf8(r.to_vec()).unwrap());
        });
        assert_eq!(got, [format!("{want}\r\n")], "`> {sent}`");
        exchanges += 1;
    }
    assert!(exchanges >= 20, "{exchanges} exchanges found");
}
