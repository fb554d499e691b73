//! The developer guide's code is the code: every ```` ```rust ```` block
//! of the book is an mdBook `{{#include file:anchor}}` of a file that is
//! compiled, whose anchor exists; and the architecture page's table of the
//! core's modules has every module of `crates/core/src/lib.rs`.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Pages whose samples another change brings to this rule.
const NOT_YET: [&str; 1] = ["adding-a-board.md"];

/// The problems of one page's Rust blocks; `page` is its path.
fn rust_blocks(page: &Path, text: &str) -> Vec<String> {
    let mut problems = Vec::new();
    let mut in_rust = None;
    for (at, line) in text.lines().enumerate() {
        let at = at + 1;
        if in_rust.is_some() {
            if line.starts_with("```") {
                in_rust = None;
                continue;
            }
            let include = line
                .trim()
                .strip_prefix("{{#include ")
                .and_then(|l| l.strip_suffix("}}"));
            let Some((file, anchor)) = include.and_then(|i| i.rsplit_once(':')) else {
                problems.push(format!(
                    "{}:{at}: not an {{{{#include file:anchor}}}}: {line}",
                    page.display()
                ));
                continue;
            };
            let source = page.parent().unwrap().join(file);
            let code = std::fs::read_to_string(&source).unwrap_or_default();
            let start = code
                .lines()
                .any(|l| l.trim() == format!("// ANCHOR: {anchor}"));
            let end = code
                .lines()
                .any(|l| l.trim() == format!("// ANCHOR_END: {anchor}"));
            if !(start && end) {
                problems.push(format!(
                    "{}:{at}: {file} has no anchor `{anchor}`",
                    page.display()
                ));
            }
        } else if line.starts_with("```rust") {
            in_rust = Some(at);
        }
    }
    problems
}

#[test]
fn every_rust_sample_of_the_book_is_included_from_compiled_code() {
    let mut problems = Vec::new();
    let mut pages = 0;
    for dir in ["docs/user", "docs/dev", "docs/design"] {
        for entry in std::fs::read_dir(root().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if !name.ends_with(".md") || NOT_YET.contains(&name.as_str()) {
                continue;
            }
            pages += 1;
            let text = std::fs::read_to_string(&path).unwrap();
            problems.extend(rust_blocks(&path, &text));
        }
    }
    assert!(pages >= 20, "{pages} pages");
    assert!(problems.is_empty(), "\n{}", problems.join("\n"));
}

#[test]
fn a_typed_sample_or_a_missing_anchor_is_named() {
    let page = root().join("docs/dev/page.md");
    let text = "```rust\nfn typed() {}\n```\n\n```rust\n\
                {{#include ../../crates/core/src/gestures.rs:nod}}\n\
                {{#include ../../crates/core/src/gestures.rs:sway}}\n```\n";
    let problems = rust_blocks(&page, text);
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(problems[0].ends_with("page.md:2: not an {{#include file:anchor}}: fn typed() {}"));
    assert!(
        problems[1].ends_with("page.md:7: ../../crates/core/src/gestures.rs has no anchor `sway`")
    );
}

#[test]
fn the_architecture_page_lists_every_module_of_the_core() {
    let lib = std::fs::read_to_string(root().join("crates/core/src/lib.rs")).unwrap();
    let page = std::fs::read_to_string(root().join("docs/dev/architecture.md")).unwrap();
    let rows: Vec<&str> = page.lines().filter(|l| l.starts_with("| `")).collect();
    let mut modules = 0;
    for line in lib.lines() {
        let Some(name) = line
            .strip_prefix("pub mod ")
            .and_then(|l| l.strip_suffix(';'))
        else {
            continue;
        };
        modules += 1;
        let named = format!("`{name}`");
        let row = rows.iter().any(|row| {
            row.split(" | ")
                .next()
                .is_some_and(|first| first.contains(&named))
        });
        assert!(
            row,
            "docs/dev/architecture.md has no row for the core's module {named}"
        );
    }
    assert!(modules >= 20, "{modules} modules");
}
