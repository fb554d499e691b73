//! The QEMU log kept on file (`boards/qemu/expected.log`), compared on every
//! test run with snapbox. A `[..]` in a line matches any text within it;
//! since snapbox pairs lines by position, each line of the run that a
//! wildcard line matches is first replaced by it, so that re-recording
//! (`--bless`) keeps the wildcards that still match.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use snapbox::{Assert, Data, filter::NormalizeToExpected};

use crate::{log::Run, project};

/// At most this many lines of a difference are printed; the full log is
/// written to the target directory.
const MAX_DIFF_LINES: usize = 200;

/// Snapbox's wildcard within a line.
const WILDCARD: &str = "[..]";

/// `qemu/expected.log`.
pub fn expected_path() -> PathBuf {
    project::root().join("boards/qemu/expected.log")
}

/// Re-records the expected log from `run`, keeping the wildcard lines that
/// still match.
pub fn bless(run: &Run) -> Result<()> {
    let path = expected_path();
    let name = project::relative(&path);
    if record(&path, &run.text())? {
        println!("re-recorded {} ({} lines)", name.display(), run.log.len());
    } else {
        println!(
            "{} already matches this run ({} lines)",
            name.display(),
            run.log.len()
        );
    }
    Ok(())
}

/// Compares `run` with the expected log; prints the difference and fails on
/// one. The actual log is also written to `actual` for inspection.
pub fn compare(run: &Run, actual: &Path) -> Result<()> {
    let path = expected_path();
    let expected_name = project::relative(&path).display().to_string();
    let actual_name = project::relative(actual).display().to_string();
    let got = run.text();
    if let Some(dir) = actual.parent() {
        std::fs::create_dir_all(dir).ok();
    }
    std::fs::write(actual, &got).with_context(|| format!("writing {}", actual.display()))?;
    if !path.exists() {
        bail!("no expected log at {expected_name}; record one with `cargo xtask test --bless`");
    }
    let Err(difference) = check(&path, &got) else {
        println!("log matches {expected_name} ({} lines)", run.log.len());
        return Ok(());
    };
    let lines: Vec<&str> = difference.lines().collect();
    for line in lines.iter().take(MAX_DIFF_LINES) {
        println!("{line}");
    }
    if lines.len() > MAX_DIFF_LINES {
        println!(
            "... {} more lines of difference; see {actual_name}",
            lines.len() - MAX_DIFF_LINES
        );
    }
    bail!(
        "the QEMU log differs from {expected_name} (full log in {actual_name}); \
         if the change is intended, re-record with `cargo xtask test --bless`"
    )
}

/// Snapbox's verdict on the log `got` against the file at `path`: `Err`
/// holds the difference.
fn check(path: &Path, got: &str) -> Result<(), String> {
    let want = std::fs::read_to_string(path).unwrap_or_default();
    assert()
        .try_eq(
            Some(&"this run"),
            Data::text(with_wildcards(&want, got)),
            Data::read_from(path, None),
        )
        .map_err(|error| error.to_string())
}

/// Writes the log `got` to `path` as snapbox reads it against the file there
/// (the wildcard lines that match kept), if that differs from the file.
/// Returns whether it wrote.
fn record(path: &Path, got: &str) -> Result<bool> {
    let want = std::fs::read_to_string(path).unwrap_or_default();
    let (actual, expected) = assert().normalize(
        Data::text(with_wildcards(&want, got)),
        Data::read_from(path, None),
    );
    if actual == expected {
        return Ok(false);
    }
    actual
        .write_to_path(path)
        .map_err(|error| anyhow!("{error}"))?;
    Ok(true)
}

/// Snapbox, reading the log as text (no path separators to normalise).
fn assert() -> Assert {
    Assert::new().normalize_paths(false)
}

/// `got` with each line that a wildcard line of `want` matches replaced by
/// that wildcard line (the first one that matches).
fn with_wildcards(want: &str, got: &str) -> String {
    let patterns: Vec<&str> = want
        .lines()
        .filter(|line| line.contains(WILDCARD))
        .collect();
    got.lines()
        .map(|line| {
            patterns
                .iter()
                .copied()
                .find(|pattern| matches(pattern, line))
                .unwrap_or(line)
        })
        .flat_map(|line| [line, "\n"])
        .collect()
}

/// Whether snapbox matches `line` against the expected line `pattern`.
fn matches(pattern: &str, line: &str) -> bool {
    let normalized = NormalizeToExpected::new()
        .redact()
        .normalize(Data::text(line), &Data::text(pattern));
    normalized.render().as_deref() == Some(pattern)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wildcards_match_within_a_line() {
        assert!(matches("a [..] c", "a b c"));
        assert!(matches("a [..] c", "a  c"));
        assert!(matches("[..]", "anything"));
        assert!(matches("x=[..] y=[..]", "x=1 y=22"));
        assert!(!matches("x=[..] y=[..]", "x=1 z=22"));
        assert!(!matches("a [..] c", "a b d"));
        assert!(!matches("plain", "plain text"));
    }

    /// A scratch copy of an expected log holding `text`.
    fn scratch(text: &str) -> (tempfile::TempDir, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("expected.log");
        std::fs::write(&path, text).unwrap();
        (dir, path)
    }

    const WANT: &str = "INFO  start\n\
                        INFO  cost [..] insns\n\
                        INFO  end 1\n\
                        INFO  timing: at most [..] us late\n";

    #[test]
    fn values_under_wildcards_may_change() {
        let (_dir, file) = scratch(WANT);
        let got =
            "INFO  start\nINFO  cost 42 insns\nINFO  end 1\nINFO  timing: at most 97 us late\n";
        assert_eq!(check(&file, got), Ok(()));
        let got = got.replace("end 1", "end 2");
        let difference = check(&file, &got).unwrap_err();
        assert!(difference.contains("end 1") && difference.contains("end 2"));
        assert!(!difference.contains("cost 42"), "{difference}");
    }

    #[test]
    fn blessing_keeps_the_wildcards_that_still_match() {
        let (_dir, file) = scratch(WANT);
        // A line added above both wildcard lines, one changed between them,
        // and new values under the wildcards.
        let got = "INFO  start\n\
                   INFO  a new line\n\
                   INFO  cost 7 insns\n\
                   INFO  end 2\n\
                   INFO  timing: at most 12 us late\n";
        assert!(record(&file, got).unwrap());
        assert_eq!(
            std::fs::read_to_string(&file).unwrap(),
            "INFO  start\n\
             INFO  a new line\n\
             INFO  cost [..] insns\n\
             INFO  end 2\n\
             INFO  timing: at most [..] us late\n"
        );
        // The re-recorded file now matches the run, and is left alone.
        assert_eq!(check(&file, got), Ok(()));
        assert!(!record(&file, got).unwrap());
    }

    #[test]
    fn blessing_drops_a_wildcard_line_that_no_longer_matches() {
        let (_dir, file) = scratch(WANT);
        let got = "INFO  start\nINFO  cost: 7\nINFO  end 1\nINFO  timing: at most 3 us late\n";
        assert!(record(&file, got).unwrap());
        assert_eq!(
            std::fs::read_to_string(&file).unwrap(),
            "INFO  start\nINFO  cost: 7\nINFO  end 1\nINFO  timing: at most [..] us late\n"
        );
    }
}
