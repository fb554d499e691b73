//! Measured figures: the commands that measure write their tables into
//! `docs/design/figures.md` ([`record`]); `cargo xtask test` fails when
//! what it measured changed the page ([`stale`]).

// Sizes and counts are far below 2^52: the float conversions are exact.
#![allow(clippy::cast_precision_loss)]

use std::{collections::BTreeMap, fmt::Write as _, path::Path};

use anyhow::{Context, Result, bail};

use crate::project;

pub const STAGE: &str = "figures page: docs/design/figures.md has what this run measured";

/// The page, from the repository's root.
pub const PAGE: &str = "docs/design/figures.md";

/// The page's sections: the title, the keys of the tables under it (a key
/// is a prefix: `image ` takes every image's), and how to measure them.
const SECTIONS: [(&str, &[&str], &str); 5] = [
    ("Memory", &["image ", "ram"], TEST),
    ("Frame cost", &["frames", "latency"], TEST),
    ("Tracking", &["tracking"], TEST),
    ("Boot precompute", &["precompute"], TEST),
    ("Idle loop sets", &["qemu"], TEST),
];
const TEST: &str = "`cargo xtask test` measures these";

/// The line above each table that names it (a command replaces its own).
const MARK: (&str, &str) = ("<!-- figures: ", " -->");

/// `1234567` as `1,234,567`.
pub fn thousands(value: u64) -> String {
    match value {
        0..1000 => value.to_string(),
        _ => format!("{},{:03}", thousands(value / 1000), value % 1000),
    }
}

/// `value` bytes, with separators.
pub fn bytes(value: u64) -> String {
    format!("{} B", thousands(value))
}

/// `value` bytes in KiB.
pub fn kib(value: u64) -> String {
    format!("{:.1} KiB", value as f64 / 1024.0)
}

/// `part` bytes against a ceiling, if there is one: `62 % of 196,608 B`.
pub fn of_ceiling(part: u64, ceiling: Option<u64>) -> String {
    let Some(whole) = ceiling else {
        return "no ceiling".to_owned();
    };
    let percent = part as f64 / whole.max(1) as f64 * 100.0;
    format!("{percent:.0} % of {}", bytes(whole))
}

/// Prints the table `key` (`intro` above it) and writes it into the page in
/// place of the one there; failing to write is reported, not an error.
#[allow(clippy::needless_pass_by_value)] // the callers hand their tables over
pub fn record(key: &str, intro: String, header: &[&str], rows: Vec<Vec<String>>) {
    println!("{key}:\n  | {} |", header.join(" | "));
    for row in &rows {
        println!("  | {} |", row.join(" | "));
    }
    let path = project::root().join(PAGE);
    match update(&path, key, render_table(&intro, header, &rows)) {
        Ok(false) => println!("  ({key}: as {PAGE} has it)"),
        Ok(true) => println!("  ({key}: written into {PAGE}, which changed: commit it)"),
        Err(error) => println!("warning: {key} not written into {PAGE}: {error:#}"),
    }
}

/// Writes `table` as `key`'s into the page at `path`; whether it changed.
fn update(path: &Path, key: &str, table: String) -> Result<bool> {
    let old = read(path)?;
    let mut tables = parse(&old);
    tables.insert(key.to_owned(), table);
    let new = render(&tables);
    if new == old {
        return Ok(false);
    }
    project::write(path, &new)?;
    Ok(true)
}

/// The page's text; empty if there is none.
pub fn read(path: &Path) -> Result<String> {
    match std::fs::read_to_string(path) {
        Ok(text) => Ok(text),
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => Ok(String::new()),
        Err(error) => Err(error).with_context(|| format!("reading {}", path.display())),
    }
}

/// Fails, naming the tables, if the page at `path` is no longer `before`:
/// what this run measured differs from what was committed. The page is
/// written already; committing it is what is left.
pub fn stale(path: &Path, before: &str) -> Result<()> {
    let after = read(path)?;
    if after == before {
        println!("{PAGE}: every table this run measured is as the page has it");
        return Ok(());
    }
    let (old, new) = (parse(before), parse(&after));
    let changed: Vec<&str> = (new.iter())
        .filter(|(key, text)| old.get(*key) != Some(*text))
        .map(|(key, _)| key.as_str())
        .collect();
    bail!(
        "{PAGE} was stale ({}): it is written with this run's figures now; review the \
         diff and commit it",
        changed.join(", ")
    )
}

/// The tables of a page, each as its text (up to the next mark or heading),
/// by key.
fn parse(page: &str) -> BTreeMap<String, String> {
    let table = |marked: &str| {
        let (key, text) = marked.split_once(MARK.1)?;
        let text = text.split("\n## ").next().unwrap_or_default();
        Some((key.to_owned(), text.trim().to_owned()))
    };
    page.split(MARK.0).skip(1).filter_map(table).collect()
}

fn render_table(intro: &str, header: &[&str], rows: &[Vec<String>]) -> String {
    let mut out = format!(
        "{intro}\n\n| {} |\n|{}\n",
        header.join(" | "),
        " --- |".repeat(header.len())
    );
    for row in rows {
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }
    out.trim().to_owned()
}

/// The page: every heading whether or not its figures are there, so that
/// the links to it resolve.
fn render(tables: &BTreeMap<String, String>) -> String {
    let mut out = String::from(
        "# Measured figures\n\n\
         <!-- Written by the commands that measure (`cargo xtask test`, `bench`): \
         do not edit. -->\n\n\
         These figures are written by the project's tools as they measure, never by \
         hand. `cargo xtask test` measures the images' sizes, their RAM with the peak \
         stack, the QEMU run, the benchmark, the latency rows and the tracking figures, \
         writes them here and fails when this page said otherwise (commit the page it \
         wrote); `cargo xtask bench` measures the benchmark, the tracking figures and \
         the latency rows.\n",
    );
    for (title, keys, how) in SECTIONS {
        let _ = write!(out, "\n## {title}\n");
        let mut any = false;
        for (key, text) in keys
            .iter()
            .flat_map(|prefix| tables.iter().filter(move |(k, _)| k.starts_with(prefix)))
        {
            any = true;
            let _ = write!(out, "\n{}{key}{}\n\n{text}\n", MARK.0, MARK.1);
        }
        if !any {
            let _ = write!(out, "\nNot measured yet: {how}.\n");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_are_replaced_the_others_kept_and_every_heading_shown() {
        assert_eq!(
            [0, 999, 1000, 133_967_040].map(thousands),
            ["0", "999", "1,000", "133,967,040"]
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("figures.md");
        let table = |value: &str| {
            render_table(
                "Sizes.",
                &["image", "flash"],
                &[vec!["pico".into(), value.into()]],
            )
        };
        assert!(update(&path, "image pico", table("100 B")).unwrap());
        assert!(update(&path, "qemu", table("7")).unwrap());
        let before = read(&path).unwrap();
        // The same figures again: the page stays as it is.
        assert!(!update(&path, "image pico", table("100 B")).unwrap());
        stale(&path, &before).unwrap();
        assert!(update(&path, "image pico", table("200 B")).unwrap());
        let page = read(&path).unwrap();
        assert_eq!(parse(&page).len(), 2);
        assert!(page.contains(
            "## Memory\n\n<!-- figures: image pico -->\n\nSizes.\n\n\
             | image | flash |\n| --- | --- |\n| pico | 200 B |\n"
        ));
        assert!(!page.contains("100 B"));
        assert!(page.contains("## Idle loop sets\n\n<!-- figures: qemu -->\n\nSizes."));
        // A run that measured other figures than the page had fails, naming them.
        let error = stale(&path, &before).unwrap_err().to_string();
        assert!(error.contains("was stale (image pico)"), "{error}");
        // Rendering what was parsed gives the page back.
        assert_eq!(render(&parse(&page)), page);
    }
}
