//! The paths the source's comments name must exist: a comment that points
//! at a file since moved or renamed misleads the next reader. [`missing`]
//! scans the comments of the Rust files and manifests under [`SCANNED`]
//! for repository paths and lists those that are not there; the unit test
//! below fails naming them. Module docs in `crates/` stay short too
//! ([`long_module_docs`]).

use std::fs;
use std::path::{Path, PathBuf};

/// The folders whose comments are scanned, from the repository root (the
/// project commands' own included).
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

/// A path named in a comment that does not exist.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Missing {
    /// The file whose comment names it, from the repository root.
    pub file: PathBuf,
    /// Its line, from 1.
    pub line: usize,
    /// The path as the comment spells it.
    pub path: String,
}

impl std::fmt::Display for Missing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}: {}", self.file.display(), self.line, self.path)
    }
}

/// The comment of a source line, if it has one: what follows `//` in a
/// Rust file, `#` in a manifest (a rough cut: a `//` or `#` inside a
/// string counts too, which only makes the scan look at more text).
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

/// Whether `path`, named in `file`, exists: from the repository root, or
/// from the package `file` belongs to (a board's `src/main.rs`).
fn exists(root: &Path, file: &Path, path: &str) -> bool {
    if root.join(path).exists() {
        return true;
    }
    file.ancestors()
        .skip(1)
        .take_while(|dir| dir.starts_with(root) && *dir != root)
        .any(|dir| dir.join("Cargo.toml").exists() && dir.join(path).exists())
}

/// Every path named in a comment under `root`'s [`SCANNED`] folders that
/// does not exist, in file and line order.
///
/// # Errors
/// A folder or file that cannot be read.
pub fn missing(root: &Path) -> anyhow::Result<Vec<Missing>> {
    let mut files = Vec::new();
    for dir in SCANNED {
        collect(&root.join(dir), &mut files)?;
    }
    files.sort();
    let mut found = Vec::new();
    for file in files {
        let rust = file.extension().is_some_and(|e| e == "rs");
        let text = fs::read_to_string(&file)?;
        for (n, line) in text.lines().enumerate() {
            let Some(comment) = comment(line, rust) else {
                continue;
            };
            for path in paths_in(comment) {
                if !exists(root, &file, path) {
                    found.push(Missing {
                        file: file.strip_prefix(root).unwrap_or(&file).to_path_buf(),
                        line: n + 1,
                        path: path.to_owned(),
                    });
                }
            }
        }
    }
    Ok(found)
}

/// The longest a module doc in `crates/` may be: what the module is and
/// its invariants; the reasoning goes to the book (`docs/design/code.md`).
pub const MODULE_DOC_LINES: usize = 30;

/// The Rust files under `root`'s `crates/` whose module doc (the `//!`
/// lines it opens with) is [`MODULE_DOC_LINES`] long or longer, with its
/// length.
///
/// # Errors
/// A folder or file that cannot be read.
pub fn long_module_docs(root: &Path) -> anyhow::Result<Vec<(PathBuf, usize)>> {
    let mut files = Vec::new();
    collect(&root.join("crates"), &mut files)?;
    files.sort();
    let mut long = Vec::new();
    for file in files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "rs"))
    {
        let text = fs::read_to_string(file)?;
        let lines = text
            .lines()
            .skip_while(|l| !l.starts_with("//!"))
            .take_while(|l| l.starts_with("//!"))
            .count();
        if lines >= MODULE_DOC_LINES {
            long.push((file.strip_prefix(root).unwrap_or(file).to_path_buf(), lines));
        }
    }
    Ok(long)
}

/// The Rust files and manifests under `dir`, build output left out.
fn collect(dir: &Path, files: &mut Vec<PathBuf>) -> anyhow::Result<()> {
    for entry in fs::read_dir(dir)? {
        let path = entry?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if path.is_dir() {
            if name != "target" && !name.starts_with('.') {
                collect(&path, files)?;
            }
        } else if path.extension().is_some_and(|e| e == "rs") || name == "Cargo.toml" {
            files.push(path);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_told_from_words() {
        assert_eq!(
            paths_in(" see `crates/core/src/lib.rs`, docs/design/idle.md and boards/qemu/."),
            [
                "crates/core/src/lib.rs",
                "docs/design/idle.md",
                "boards/qemu/"
            ]
        );
        // Not repository paths: a crate's name, a URL, an elision; of a
        // glob, the folder.
        assert!(paths_in("idle_head_core::console, https://docs.rs/x/y.html").is_empty());
        assert_eq!(
            paths_in("docs/design/*.md, src/...rs, the src/ folder's"),
            ["docs/design/", "src/"]
        );
    }

    #[test]
    fn a_path_that_is_not_there_is_named() {
        let root = crate::project::root();
        let file = root.join("crates/core/src/lib.rs");
        assert!(exists(&root, &file, "crates/core/src/lib.rs"));
        // From the package's folder.
        assert!(exists(
            &root,
            &root.join("boards/qemu/src/main.rs"),
            "src/panic_proof.rs"
        ));
        assert!(!exists(&root, &file, "crates/core/src/gone.rs"));
        assert!(!exists(&root, &file, "src/bin/pico/"));
    }

    #[test]
    fn module_docs_are_short() {
        let long = long_module_docs(&crate::project::root()).unwrap();
        let list: Vec<String> = long
            .iter()
            .map(|(file, n)| format!("{}: {n} lines", file.display()))
            .collect();
        assert!(
            list.is_empty(),
            "module docs of {MODULE_DOC_LINES} lines or more (say what the module is; \
             the reasoning goes to docs/design/code.md):\n{}",
            list.join("\n")
        );
    }

    #[test]
    fn every_path_a_comment_names_exists() {
        let missing = missing(&crate::project::root()).unwrap();
        let list: Vec<String> = missing.iter().map(ToString::to_string).collect();
        assert!(
            list.is_empty(),
            "comments name paths that do not exist:\n{}",
            list.join("\n")
        );
    }
}
