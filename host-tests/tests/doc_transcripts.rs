//! Every example exchange in the README and the book is what the console
//! does. A transcript is a ```` ```text ```` block with `> line`s in it:
//! each `> line` is sent to the firmware's console service on a simulated
//! head (built-in settings, one frame played after each line, and the
//! frames a queued action's reply waits for), and the `< ` lines under it
//! are its reply, byte for byte. Each file plays on a fresh head, its
//! transcripts in the order of the file, so one example may build on the
//! one before it.
//!
//! An HTML comment right above a block's fence changes how it plays
//! (`docs/dev/tests.md` explains them to writers):
//!
//! - `<!-- transcript: after "servo rate 200" "save" -->`: those lines are
//!   sent first, each must be answered `ok`, their replies are not shown;
//! - `<!-- transcript: live -->`: the replies are a running head's (a
//!   DMX signal, radar frames, counters): the value of every `key=value`
//!   matches any value, and any other run of digits any digits;
//! - `<!-- transcript: replayed by host-tests/tests/bottango.rs -->`: the
//!   block is another protocol's, replayed by that test (which must name
//!   the file).
//!
//! A mismatch fails with the file and line, the expected reply and the
//! one given. `BLESS=1 cargo test doc_transcripts::` writes the
//! replies given into the documents instead (single-line replies of plain
//! blocks only; review the diff).

use std::path::{Path, PathBuf};

use host_tests::console::head::{SimFrames, service, shared};
use idle_head_core::console::PortSession;

/// How a block plays, from the comment above it.
#[derive(Debug, Default)]
struct Marker {
    after: Vec<String>,
    live: bool,
    replayed_by: Option<String>,
}

impl Marker {
    fn parse(text: &str, at: &str) -> Self {
        let mut marker = Self::default();
        let mut rest = text.trim();
        while !rest.is_empty() {
            if let Some(after) = rest.strip_prefix("after ") {
                rest = after.trim_start();
                while let Some(quoted) = rest.strip_prefix('"') {
                    let end = quoted
                        .find('"')
                        .unwrap_or_else(|| panic!("{at}: unclosed quote in the marker"));
                    marker.after.push(quoted[..end].to_owned());
                    rest = quoted[end + 1..].trim_start();
                }
            } else if let Some(after) = rest.strip_prefix("live") {
                marker.live = true;
                rest = after.trim_start();
            } else if let Some(after) = rest.strip_prefix("replayed by ") {
                marker.replayed_by = Some(after.trim().to_owned());
                rest = "";
            } else {
                panic!("{at}: unknown transcript marker `{rest}`");
            }
        }
        marker
    }
}

/// One `> line` and the reply lines under it; `at` is its 0-based line.
struct Exchange {
    at: usize,
    sent: String,
    want: Vec<String>,
}

struct Block {
    marker: Marker,
    exchanges: Vec<Exchange>,
}

/// The transcripts of a document, in order.
fn transcripts(name: &str, doc: &str) -> Vec<Block> {
    let lines: Vec<&str> = doc.lines().collect();
    let mut blocks = Vec::new();
    let mut marker: Option<(usize, Marker)> = None;
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim();
        if let Some(text) = line
            .strip_prefix("<!-- transcript:")
            .and_then(|l| l.strip_suffix("-->"))
        {
            marker = Some((i, Marker::parse(text, &format!("{name}:{}", i + 1))));
            i += 1;
            continue;
        }
        if !lines[i].starts_with("```") {
            i += 1;
            continue;
        }
        let text = lines[i] == "```text";
        let end = (i + 1..lines.len())
            .find(|&j| lines[j].starts_with("```"))
            .unwrap_or_else(|| panic!("{name}:{}: unclosed fence", i + 1));
        let mut exchanges: Vec<Exchange> = Vec::new();
        let body = || lines.iter().enumerate().take(end).skip(i + 1);
        let sends = body().any(|(_, line)| line.starts_with("> "));
        for (j, line) in body().filter(|_| text && sends) {
            if let Some(sent) = line.strip_prefix("> ") {
                exchanges.push(Exchange {
                    at: j,
                    sent: sent.to_owned(),
                    want: Vec::new(),
                });
            } else if let Some(reply) = line.strip_prefix('<') {
                let reply = reply.strip_prefix(' ').unwrap_or(reply);
                let exchange = exchanges
                    .last_mut()
                    .unwrap_or_else(|| panic!("{name}:{}: a reply before any line", j + 1));
                exchange.want.push(reply.to_owned());
            }
        }
        let fence = marker.take();
        if text && !exchanges.is_empty() {
            let marker = match fence {
                Some((at, marker)) if at + 1 == i => marker,
                Some((at, _)) => panic!("{name}:{}: a marker not right above a fence", at + 1),
                None => Marker::default(),
            };
            blocks.push(Block { marker, exchanges });
        } else if let Some((at, _)) = fence {
            panic!("{name}:{}: a transcript marker above no transcript", at + 1);
        }
        i = end + 1;
    }
    blocks
}

/// A running head's reply with its values left out: every `key=value`
/// as `key=…`, every other run of digits as `#`.
fn values_as_any(line: &str) -> String {
    let words = line.split(' ').map(|word| match word.split_once('=') {
        Some((key, _)) => format!("{key}=…"),
        None => {
            let mut out = String::new();
            for c in word.chars() {
                if !c.is_ascii_digit() {
                    out.push(c);
                } else if !out.ends_with('#') {
                    out.push('#');
                }
            }
            out
        }
    });
    words.collect::<Vec<_>>().join(" ")
}

/// A simulated head behind a console port.
struct Head {
    queue: &'static idle_head_core::behaviour::CommandQueue,
    link: &'static idle_head_core::console::ConsoleLink,
    frames: SimFrames,
    handler: idle_head_core::console::ConsoleService<'static, idle_head_core::settings::RamStorage>,
    session: PortSession,
}

impl Head {
    fn new() -> Self {
        let (queue, link) = shared();
        Self {
            queue,
            link,
            frames: SimFrames::new(),
            handler: service(queue, link),
            session: PortSession::new(),
        }
    }

    /// Sends `line`; its reply lines, without their line ends.
    fn send(&mut self, line: &str) -> Vec<String> {
        let mut got = String::new();
        for &byte in format!("{line}\r\n").as_bytes() {
            if let Some(r) = self.session.push(byte, &mut self.handler) {
                got.push_str(std::str::from_utf8(r).unwrap());
            }
            // A queued action's reply: once the frame task took it.
            if let Some(r) = self
                .frames
                .finish(&mut self.session, self.queue, self.link, 0)
            {
                got.push_str(std::str::from_utf8(r).unwrap());
            }
        }
        self.frames.frame(self.queue, self.link);
        got.split_terminator('\n')
            .map(|l| l.trim_end_matches('\r').to_owned())
            .collect()
    }
}

/// The README and every page of the book.
fn documents() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).expect("docs/") {
            let path = entry.expect("docs/").path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut out = vec![root.join("README.md")];
    walk(&root.join("docs"), &mut out);
    out.sort();
    out
}

/// Replays the transcripts of one document; the mismatches, and the
/// exchanges played.
fn replay(name: &str, doc: &str, bless: Option<&mut Vec<String>>) -> (Vec<String>, usize) {
    let mut failures = Vec::new();
    let mut head = Head::new();
    let mut played = 0;
    let mut bless = bless;
    for block in transcripts(name, doc) {
        if let Some(test) = &block.marker.replayed_by {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(test);
            let source = std::fs::read_to_string(&path).unwrap_or_default();
            let doc_path = name.trim_start_matches("./");
            if !source.contains(doc_path) {
                failures.push(format!("{name}: `{test}` does not replay {doc_path}"));
            }
            continue;
        }
        for line in &block.marker.after {
            let got = head.send(line);
            if !got.first().is_some_and(|r| r.starts_with("ok")) {
                failures.push(format!("{name}: setup `{line}` answered {got:?}"));
            }
        }
        for exchange in block.exchanges {
            let got = head.send(&exchange.sent);
            played += 1;
            let same = if block.marker.live {
                let any = |lines: &[String]| -> Vec<String> {
                    lines.iter().map(|l| values_as_any(l)).collect()
                };
                any(&got) == any(&exchange.want)
            } else {
                got == exchange.want
            };
            if same {
                continue;
            }
            if let Some(lines) = bless.as_deref_mut()
                && !block.marker.live
                && got.len() == 1
                && exchange.want.len() == 1
            {
                lines[exchange.at + 1] = format!("< {}", got[0]);
                continue;
            }
            failures.push(format!(
                "{name}:{}: `> {}`\n  expected: {:?}\n  got:      {:?}",
                exchange.at + 1,
                exchange.sent,
                exchange.want,
                got
            ));
        }
    }
    (failures, played)
}

#[test]
fn every_example_exchange_in_the_readme_and_the_book_holds() {
    let bless = std::env::var_os("BLESS").is_some();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut failures = Vec::new();
    let mut played = Vec::new();
    for path in documents() {
        let doc = std::fs::read_to_string(&path).expect("a document");
        let name = path
            .strip_prefix(&root)
            .unwrap_or(&path)
            .display()
            .to_string();
        let mut lines: Vec<String> = doc.lines().map(str::to_owned).collect();
        let (failed, count) = replay(&name, &doc, bless.then_some(&mut lines));
        if bless {
            std::fs::write(&path, lines.join("\n") + "\n").expect("a document");
        }
        failures.extend(failed);
        if count > 0 {
            played.push((name, count));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
    let count = |file: &str| {
        played
            .iter()
            .find(|(name, _)| name == file)
            .map_or(0, |(_, n)| *n)
    };
    // The protocol's reference has an example of nearly every command; the
    // README's calibration is replayed too.
    assert!(count("docs/user/protocol.md") >= 20, "{played:?}");
    assert!(count("README.md") >= 3, "{played:?}");
}

#[test]
fn a_wrong_reply_is_named_with_its_file_and_line() {
    let doc = "Text.\n\n```text\n> status\n< ok\n```\n\n<!-- transcript: live -->\n\
               ```text\n> help\n< ok commands: 1\n```\n";
    let (failures, played) = replay("page.md", doc, None);
    assert_eq!(played, 2);
    assert_eq!(failures.len(), 2, "{failures:?}");
    assert!(failures[0].starts_with("page.md:4: `> status`\n  expected: [\"ok\"]"));
    assert!(failures[1].starts_with("page.md:10: `> help`"));
    // A setup line answered `err` fails; digits are wildcards in a live block.
    let doc = "<!-- transcript: after \"servo rate 20\" -->\n```text\n> servo rate\n< ok 50\n```\n";
    let (failures, _) = replay("page.md", doc, None);
    assert!(failures[0].starts_with("page.md: setup `servo rate 20`"));
    assert_eq!(values_as_any("ok a=12 b=on 40 ms"), "ok a=… b=… # ms");
    // The state a setup line makes is there for the block.
    let doc = "<!-- transcript: after \"servo rate 200\" -->\n```text\n> servo rate\n\
               < ok servo rate=200 period_us=5000\n```\n";
    assert_eq!(replay("page.md", doc, None), (vec![], 1));
    // A block another test replays must be named by it.
    let doc =
        "<!-- transcript: replayed by host-tests/tests/seeds.rs -->\n```text\n> x\n< y\n```\n";
    let (failures, played) = replay("docs/user/page.md", doc, None);
    assert_eq!(played, 0);
    assert!(
        failures[0].contains("does not replay docs/user/page.md"),
        "{failures:?}"
    );
}
