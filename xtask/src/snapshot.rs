//! The expected QEMU log (`boards/qemu/expected.log`), compared with
//! snapbox; a run's line a `[..]` line matches is replaced by it first, so
//! that `--bless` keeps the wildcards that still match.

use std::path::Path;

use anyhow::{Result, anyhow, bail};
use snapbox::{Assert, Data, filter::NormalizeToExpected};

use crate::{log::Run, project};

const MAX_DIFF_LINES: usize = 200;

const EXPECTED: &str = "boards/qemu/expected.log";

pub fn bless(run: &Run) -> Result<()> {
    let path = project::root().join(EXPECTED);
    let done = if record(&path, &run.text())? {
        "re-recorded"
    } else {
        "already matches this run"
    };
    let (path, lines) = (project::relative(&path), run.log.len());
    println!("{} {done} ({lines} lines)", path.display());
    Ok(())
}

/// Compares `run` with the expected log, writing it to `actual`; prints
/// the difference and fails on one.
pub fn compare(run: &Run, actual: &Path) -> Result<()> {
    let path = project::root().join(EXPECTED);
    let [expected, actual_name] =
        [&path, actual].map(|p| project::relative(p).display().to_string());
    let got = run.text();
    project::write(actual, &got)?;
    if !path.exists() {
        bail!("no expected log at {expected}; record one with `cargo xtask test --bless`");
    }
    let Err(difference) = check(&path, &got) else {
        println!("log matches {expected} ({} lines)", run.log.len());
        return Ok(());
    };
    let lines: Vec<&str> = difference.lines().collect();
    for line in lines.iter().take(MAX_DIFF_LINES) {
        println!("{line}");
    }
    if lines.len() > MAX_DIFF_LINES {
        let more = lines.len() - MAX_DIFF_LINES;
        println!("... {more} more lines of difference; see {actual_name}");
    }
    bail!(
        "the QEMU log differs from {expected} (full log in {actual_name}); if the change is \
         intended, re-record with `cargo xtask test --bless`"
    )
}

/// The log `got` with the wildcards of the file at `path`, and the file.
fn against(path: &Path, got: &str) -> (Assert, Data, Data) {
    let want = std::fs::read_to_string(path).unwrap_or_default();
    let got = Data::text(with_wildcards(&want, got));
    let assert = Assert::new().normalize_paths(false);
    (assert, got, Data::read_from(path, None))
}

/// Snapbox's verdict on the log `got` against the file at `path`: `Err`
/// holds the difference.
fn check(path: &Path, got: &str) -> Result<(), String> {
    let (assert, got, want) = against(path, got);
    assert
        .try_eq(Some(&"this run"), got, want)
        .map_err(|e| e.to_string())
}

/// Writes the log `got` to `path` as snapbox reads it against the file there,
/// if that differs from the file; whether it wrote.
fn record(path: &Path, got: &str) -> Result<bool> {
    let (assert, got, want) = against(path, got);
    let (actual, expected) = assert.normalize(got, want);
    if actual == expected {
        return Ok(false);
    }
    actual
        .write_to_path(path)
        .map_err(|error| anyhow!("{error}"))?;
    Ok(true)
}

/// `got` with each line that a wildcard line of `want` matches replaced by
/// that wildcard line (the first one that matches).
fn with_wildcards(want: &str, got: &str) -> String {
    let patterns: Vec<&str> = want.lines().filter(|line| line.contains("[..]")).collect();
    let line = |line| {
        *patterns
            .iter()
            .find(|pattern| matches(pattern, line))
            .unwrap_or(&line)
    };
    got.lines().flat_map(|l| [line(l), "\n"]).collect()
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

    const WANT: &str =
        "INFO  start\nINFO  cost [..] insns\nINFO  end 1\nINFO  timing: at most [..] us late\n";

    #[test]
    fn wildcards_match_within_a_line() {
        for (pattern, line, matched) in [
            ("a [..] c", "a b c", true),
            ("a [..] c", "a  c", true),
            ("[..]", "anything", true),
            ("x=[..] y=[..]", "x=1 y=22", true),
            ("x=[..] y=[..]", "x=1 z=22", false),
            ("a [..] c", "a b d", false),
            ("plain", "plain text", false),
        ] {
            assert_eq!(matches(pattern, line), matched, "{pattern} / {line}");
        }
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("expected.log");
        std::fs::write(&file, WANT).unwrap();
        // Values under wildcards may change; a line without one may not.
        let got =
            "INFO  start\nINFO  cost 42 insns\nINFO  end 1\nINFO  timing: at most 97 us late\n";
        assert_eq!(check(&file, got), Ok(()));
        let difference = check(&file, &got.replace("end 1", "end 2")).unwrap_err();
        assert!(difference.contains("end 1") && difference.contains("end 2"));
        assert!(!difference.contains("cost 42"), "{difference}");
    }

    #[test]
    fn blessing_keeps_the_wildcards_that_still_match_and_drops_the_others() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("expected.log");
        std::fs::write(&file, WANT).unwrap();
        // A line added above both wildcard lines, one changed between them,
        // and new values under the wildcards.
        let got = "INFO  start\nINFO  a new line\nINFO  cost 7 insns\nINFO  end 2\nINFO  timing: at most 12 us late\n";
        assert!(record(&file, got).unwrap());
        assert_eq!(
            std::fs::read_to_string(&file).unwrap(),
            "INFO  start\nINFO  a new line\nINFO  cost [..] insns\nINFO  end 2\nINFO  timing: at most [..] us late\n"
        );
        // The re-recorded file now matches the run, and is left alone.
        assert_eq!(check(&file, got), Ok(()));
        assert!(!record(&file, got).unwrap());
        std::fs::write(&file, WANT).unwrap();
        let got = "INFO  start\nINFO  cost: 7\nINFO  end 1\nINFO  timing: at most 3 us late\n";
        assert!(record(&file, got).unwrap());
        let want = "INFO  start\nINFO  cost: 7\nINFO  end 1\nINFO  timing: at most [..] us late\n";
        assert_eq!(std::fs::read_to_string(&file).unwrap(), want);
    }
}
