//! Unit tests of the source's comments: every repository path one names
//! exists (a comment pointing at a moved file misleads), and module docs in
//! `crates/` stay short.

use std::fs;
use std::path::{Path, PathBuf};

pub const SCANNED: [&str; 5] = ["crates", "src", "boards", "host-tests", "xtask"];

/// How a path a comment names starts: a folder at the repository's top.
const PREFIXES: [&str; 10] = [
    "crates/",
    "src/",
    "docs/",
    "boards/",
    "host-tests/",
    "xtask/",
    "sim/",
    "panel/",
    ".cargo/",
    ".ci/",
];

/// How a path a comment names ends, if it names a file.
const EXTENSIONS: [&str; 13] = [
    ".rs", ".md", ".toml", ".x", ".mjs", ".js", ".json", ".log", ".html", ".sh", ".css", ".txt",
    ".png",
];

/// What follows `//` in a Rust line, `#` in a manifest's (inside a string
/// too, which only makes the scan look at more text).
fn comment(line: &str, rust: bool) -> Option<&str> {
    let marker = if rust { "//" } else { "#" };
    line.find(marker).map(|at| &line[at + marker.len()..])
}

/// The repository paths `text` names: words made of path characters that
/// start at a top-level folder and end in a file extension or a `/`.
pub fn paths_in(text: &str) -> Vec<&str> {
    let is_path_char = |c: char| c.is_ascii_alphanumeric() || "_./-".contains(c);
    text.split(|c: char| !is_path_char(c))
        .map(|word| word.trim_end_matches(['.', ',']))
        .filter(|word| {
            PREFIXES.iter().any(|p| word.starts_with(p))
                && !word.contains("...")
                && (word.ends_with('/') || EXTENSIONS.iter().any(|e| word.ends_with(e)))
        })
        .collect()
}

/// Whether `path`, named in `file`, exists: from the folder of a package
/// `file` is in, the repository root's or another (a board's `src/main.rs`).
fn exists(root: &Path, file: &Path, path: &str) -> bool {
    file.ancestors()
        .take_while(|dir| dir.starts_with(root))
        .any(|dir| dir.join("Cargo.toml").exists() && dir.join(path).exists())
}

/// The longest a module doc in `crates/` may be: what the module is and
/// its invariants; the reasoning goes to the book (`docs/design/code.md`).
pub const MODULE_DOC_LINES: usize = 30;

/// The Rust files and manifests under `root`'s `dirs`, build output left
/// out, in order.
fn files(root: &Path, dirs: &[&str]) -> anyhow::Result<Vec<PathBuf>> {
    let mut todo: Vec<PathBuf> = dirs.iter().map(|dir| root.join(dir)).collect();
    let mut files = Vec::new();
    while let Some(dir) = todo.pop() {
        for entry in fs::read_dir(dir)? {
            let path = entry?.path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if path.is_dir() {
                if name != "target" && !name.starts_with('.') {
                    todo.push(path);
                }
            } else if path.extension().is_some_and(|e| e == "rs") || name == "Cargo.toml" {
                files.push(path);
            }
        }
    }
    files.sort();
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::project::relative;

    #[test]
    fn paths_are_told_from_words() {
        let text = " see `crates/core/src/lib.rs`, docs/design/idle.md and boards/qemu/.";
        let paths = "crates/core/src/lib.rs docs/design/idle.md boards/qemu/";
        assert_eq!(paths_in(text).join(" "), paths);
        // Not repository paths: a crate's name, a URL, an elision; of a
        // glob, the folder.
        assert!(paths_in("idle_head_core::console, https://docs.rs/x/y.html").is_empty());
        let folders = paths_in("docs/design/*.md, src/...rs, the src/ folder's");
        assert_eq!(folders, ["docs/design/", "src/"]);
    }

    #[test]
    fn a_path_that_is_not_there_is_named() {
        let root = crate::project::root();
        let file = root.join("crates/core/src/lib.rs");
        assert!(exists(&root, &file, "crates/core/src/lib.rs"));
        // From the package's folder.
        let main = root.join("boards/qemu/src/main.rs");
        assert!(exists(&root, &main, "src/panic_proof.rs"));
        assert!(!exists(&root, &file, "crates/core/src/gone.rs"));
        assert!(!exists(&root, &file, "src/bin/pico/"));
    }

    #[test]
    fn module_docs_are_short() {
        let root = crate::project::root();
        let mut list = Vec::new();
        // A manifest has no `//!` lines: its count is 0.
        for file in files(&root, &["crates"]).unwrap() {
            let text = fs::read_to_string(&file).unwrap();
            let doc = text.lines().skip_while(|l| !l.starts_with("//!"));
            let lines = doc.take_while(|l| l.starts_with("//!")).count();
            if lines >= MODULE_DOC_LINES {
                list.push(format!("{}: {lines} lines", relative(&file).display()));
            }
        }
        assert!(
            list.is_empty(),
            "module docs of {MODULE_DOC_LINES} lines or more (say what the module is; \
             the reasoning goes to docs/design/code.md):\n{}",
            list.join("\n")
        );
    }

    /// Every path named in a comment under [`SCANNED`] exists.
    #[test]
    fn every_path_a_comment_names_exists() {
        let root = crate::project::root();
        let mut list = Vec::new();
        for file in files(&root, &SCANNED).unwrap() {
            let rust = file.extension().is_some_and(|e| e == "rs");
            let text = fs::read_to_string(&file).unwrap();
            for (n, line) in text.lines().enumerate() {
                let Some(comment) = comment(line, rust) else {
                    continue;
                };
                for path in paths_in(comment) {
                    if !exists(&root, &file, path) {
                        list.push(format!("{}:{}: {path}", relative(&file).display(), n + 1));
                    }
                }
            }
        }
        assert!(
            list.is_empty(),
            "comments name paths that do not exist:\n{}",
            list.join("\n")
        );
    }
}
