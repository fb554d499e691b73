//! The QEMU log kept on file in the QEMU package, compared on every test run.
//!
//! The expected log is the decoded log, one `LEVEL message` line per frame.
//! Where a line holds a value that changes with unrelated code changes (an
//! instruction count, a wake-up latency), that part of the line can be
//! replaced by `[..]` in the file, which matches any text within the line.
//! Re-recording (`--bless`) keeps such a line as it is while it still matches.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use similar::{Algorithm, DiffTag, TextDiff, capture_diff_slices};

use crate::{project, qemu::Run};

/// At most this many diff lines are printed; the full log is written to the
/// target directory.
const MAX_DIFF_LINES: usize = 200;

/// Matches any text within one line of the expected log.
const WILDCARD: &str = "[..]";

/// `qemu/expected.log`.
pub fn expected_path() -> PathBuf {
    project::root().join("qemu/expected.log")
}

/// The run's log as it is kept on file.
pub fn text(run: &Run) -> String {
    let mut text = String::new();
    for line in &run.log {
        text.push_str(&line.snapshot());
        text.push('\n');
    }
    text
}

/// Re-records the expected log from `run`, keeping the lines with wildcards
/// that still match.
pub fn bless(run: &Run) -> Result<()> {
    let path = expected_path();
    let got = text(run);
    let text = match std::fs::read_to_string(&path) {
        Ok(want) => project_onto(&want.replace("\r\n", "\n"), &got),
        Err(_) => got,
    };
    std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    println!(
        "re-recorded {} ({} lines)",
        relative(&path).display(),
        run.log.len()
    );
    Ok(())
}

/// Compares `run` with the expected log; prints a unified diff and fails on a
/// difference. The actual log is also written to `actual` for inspection.
pub fn compare(run: &Run, actual: &Path) -> Result<()> {
    let path = expected_path();
    let got = text(run);
    if let Some(dir) = actual.parent() {
        std::fs::create_dir_all(dir).ok();
    }
    std::fs::write(actual, &got).with_context(|| format!("writing {}", actual.display()))?;
    let Ok(want) = std::fs::read_to_string(&path) else {
        bail!(
            "no expected log at {}; record one with `cargo xtask test --bless`",
            relative(&path).display()
        );
    };
    let want = want.replace("\r\n", "\n");
    let projected = project_onto(&want, &got);
    if want == projected {
        println!(
            "log matches {} ({} lines)",
            relative(&path).display(),
            run.log.len()
        );
        return Ok(());
    }
    let expected_name = relative(&path).display().to_string();
    let actual_name = relative(actual).display().to_string();
    let diff = TextDiff::from_lines(&want, &projected);
    let diff = diff
        .unified_diff()
        .context_radius(3)
        .header(&expected_name, &actual_name)
        .to_string();
    let lines: Vec<&str> = diff.lines().collect();
    for line in lines.iter().take(MAX_DIFF_LINES) {
        println!("{line}");
    }
    if lines.len() > MAX_DIFF_LINES {
        println!(
            "... {} more diff lines; see {actual_name}",
            lines.len() - MAX_DIFF_LINES
        );
    }
    bail!(
        "the QEMU log differs from {expected_name} (full log in {actual_name}); \
         if the change is intended, re-record with `cargo xtask test --bless`"
    )
}

/// `got` with each line that an expected line matches through wildcards
/// replaced by that expected line, so that only real differences remain.
/// Lines are paired along a line diff, so inserted or removed lines do not
/// upset the pairing.
fn project_onto(want: &str, got: &str) -> String {
    let want: Vec<&str> = want.lines().collect();
    let mut projected: Vec<&str> = got.lines().collect();
    let ops = capture_diff_slices(Algorithm::Myers, &want, &projected);
    for op in ops {
        let (tag, old, new) = op.as_tag_tuple();
        if tag != DiffTag::Replace {
            continue;
        }
        // Pair each expected line, in order, with the first later line of the
        // block that it matches.
        let mut next = new.start;
        for old in old {
            if let Some(at) = (next..new.end).find(|&at| matches(want[old], projected[at])) {
                projected[at] = want[old];
                next = at + 1;
            }
        }
    }
    let mut text = projected.join("\n");
    if !text.is_empty() {
        text.push('\n');
    }
    text
}

/// Whether `line` matches `pattern`, in which each `[..]` stands for any text.
fn matches(pattern: &str, line: &str) -> bool {
    if !pattern.contains(WILDCARD) {
        return pattern == line;
    }
    let mut parts = pattern.split(WILDCARD);
    let first = parts.next().unwrap_or_default();
    let Some(mut rest) = line.strip_prefix(first) else {
        return false;
    };
    let mut parts: Vec<&str> = parts.collect();
    let last = parts.pop().unwrap_or_default();
    for part in parts {
        match rest.find(part) {
            Some(at) => rest = &rest[at + part.len()..],
            None => return false,
        }
    }
    rest.len() >= last.len() && rest.ends_with(last)
}

fn relative(path: &Path) -> &Path {
    path.strip_prefix(project::root()).unwrap_or(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wildcards_match_within_a_line() {
        assert!(matches("a [..] c", "a b c"));
        assert!(matches("a [..] c", "a  c"));
        assert!(matches("[..]", ""));
        assert!(matches("x=[..] y=[..]", "x=1 y=22"));
        assert!(!matches("x=[..] y=[..]", "x=1 z=22"));
        assert!(!matches("a [..] c", "a b d"));
        assert!(!matches("ab[..]ba", "aba"));
        assert!(!matches("plain", "plain text"));
    }

    #[test]
    fn projection_keeps_matching_wildcard_lines_and_real_differences() {
        let want = "INFO  start\nINFO  cost [..] insns\nINFO  end 1\n";
        let got = "INFO  start\nINFO  new line\nINFO  cost 42 insns\nINFO  end 2\n";
        assert_eq!(
            project_onto(want, got),
            "INFO  start\nINFO  new line\nINFO  cost [..] insns\nINFO  end 2\n"
        );
        assert_eq!(
            project_onto(want, "INFO  start\nINFO  cost 7 insns\nINFO  end 1\n"),
            want
        );
    }
}
