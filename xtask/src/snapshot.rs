//! The QEMU log kept on file next to the QEMU image, compared on every test run.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use similar::TextDiff;

use crate::{project, qemu::Run};

/// At most this many diff lines are printed; the full log is written to the
/// target directory.
const MAX_DIFF_LINES: usize = 200;

/// `src/bin/qemu/expected.log`.
pub fn expected_path() -> PathBuf {
    project::root().join("src/bin/qemu/expected.log")
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

/// Re-records the expected log from `run`.
pub fn bless(run: &Run) -> Result<()> {
    let path = expected_path();
    std::fs::write(&path, text(run)).with_context(|| format!("writing {}", path.display()))?;
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
    if want == got {
        println!(
            "log matches {} ({} lines)",
            relative(&path).display(),
            run.log.len()
        );
        return Ok(());
    }
    let expected_name = relative(&path).display().to_string();
    let actual_name = relative(actual).display().to_string();
    let diff = TextDiff::from_lines(&want, &got);
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

fn relative(path: &Path) -> &Path {
    path.strip_prefix(project::root()).unwrap_or(path)
}
