//! Measured figures: the commands that measure (`elf`, `qemu`, `bench`,
//! `metrics`) record each of their tables here as they go, kept in
//! `target/figures.json`; `cargo xtask book` writes the book's page from
//! them ([`write_page`]). No figure in the docs is typed by hand.

// Sizes and counts are far below 2^52: the float conversions are exact.
#![allow(clippy::cast_precision_loss)]

use std::{
    collections::BTreeMap,
    fmt::Write as _,
    path::{Path, PathBuf},
    process::Command,
};

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

use crate::project;

/// One table of the page, as the command that measured it recorded it: the
/// command line and the working tree's commit, what the table shows
/// (Markdown, said before it), its header and rows.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Table {
    pub command: String,
    pub commit: Option<String>,
    pub intro: String,
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

/// The page's sections: the title, the keys of the tables under it (a key
/// is a prefix: `image ` takes every image's), and how to measure them.
const SECTIONS: [(&str, &[&str], &str); 6] = [
    ("Memory", &["image ", "ram"], TEST),
    ("Frame cost", &["frames", "latency"], TEST),
    ("Tracking", &["tracking"], TEST),
    ("Boot precompute", &["precompute"], TEST),
    ("Idle loop sets", &["qemu"], TEST),
    (
        "Loop quality",
        &["metrics "],
        "run `cargo xtask metrics`, then `cargo xtask book`",
    ),
];
const TEST: &str = "`cargo xtask test` measures these (and builds this page again)";

/// Where the figures are kept: `target/figures.json`, beside the book.
pub fn path() -> PathBuf {
    project::root().join("target").join("figures.json")
}

/// `1234567` as `1,234,567`.
pub fn thousands(value: u64) -> String {
    let digits = value.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
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
    let of = |whole: u64| {
        format!(
            "{:.0} % of {}",
            part as f64 / whole.max(1) as f64 * 100.0,
            bytes(whole)
        )
    };
    ceiling.map_or_else(|| "no ceiling".to_owned(), of)
}

/// Prints the table `key` and records it (replacing the one recorded
/// before) as the running command's, on the working tree's commit. A table
/// that cannot be recorded does not fail the check that measured it: it is
/// reported, and the page shows the last one recorded.
pub fn record(key: &str, intro: String, header: &[&str], rows: Vec<Vec<String>>) {
    println!("{key}:\n  | {} |", header.join(" | "));
    for row in &rows {
        println!("  | {} |", row.join(" | "));
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    let git = Command::new("git")
        .args(["describe", "--always", "--dirty"])
        .current_dir(project::root())
        .output();
    let commit = git.ok().filter(|out| out.status.success());
    let commit = commit.map(|out| String::from_utf8_lossy(&out.stdout).trim().to_owned());
    let table = Table {
        command: format!("cargo xtask {}", args.join(" ")).trim().to_owned(),
        commit: commit.filter(|text| !text.is_empty()),
        intro,
        header: header.iter().map(|h| (*h).to_owned()).collect(),
        rows,
    };
    let path = path();
    match update_at(&path, key, table) {
        Ok(()) => println!(
            "  ({key} recorded in {})",
            project::relative(&path).display()
        ),
        Err(error) => println!("warning: {key} not recorded: {error:#}"),
    }
}

/// The tables at `path`; none if there is no file.
fn load(path: &Path) -> Result<BTreeMap<String, Table>> {
    match std::fs::read_to_string(path) {
        Ok(text) => serde_json::from_str(&text)
            .with_context(|| format!("{} holds no figures this xtask can read", path.display())),
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => Ok(BTreeMap::new()),
        Err(error) => Err(error).with_context(|| format!("reading {}", path.display())),
    }
}

/// Replaces the table `key` at `path` (through a temporary file, so that a
/// reader never sees half a file); a file this xtask cannot read (another
/// version's) is started afresh.
fn update_at(path: &Path, key: &str, table: Table) -> Result<()> {
    let mut figures = load(path).unwrap_or_else(|error| {
        println!("figures: {error:#}; starting afresh");
        BTreeMap::new()
    });
    figures.insert(key.to_owned(), table);
    let partial = path.with_extension("json.partial");
    project::write(&partial, serde_json::to_string_pretty(&figures)?)?;
    std::fs::rename(&partial, path).with_context(|| format!("writing {}", path.display()))
}

/// Writes the page to `page` from the figures at `figures_path`; returns
/// the sections that had figures. Every heading is there whether or not
/// its figures are, so that the links to it resolve.
pub fn write_page(figures_path: &Path, page: &Path) -> Result<Vec<&'static str>> {
    let figures = load(figures_path).unwrap_or_else(|error| {
        println!("figures: {error:#}; the page says how to measure");
        BTreeMap::new()
    });
    let (text, recorded) = render(&figures);
    std::fs::write(page, text).with_context(|| format!("writing {}", page.display()))?;
    Ok(recorded)
}

fn render(figures: &BTreeMap<String, Table>) -> (String, Vec<&'static str>) {
    let mut out = String::from(
        "# Measured figures\n\n\
         <!-- Written by `cargo xtask book` from target/figures.json: not in git, \
         do not edit. -->\n\n\
         These figures are written by the project's tools as they measure, never by \
         hand. `cargo xtask test` records the images' sizes, their RAM with the peak \
         stack, the QEMU run, the benchmark and the tracking figures; `cargo xtask \
         bench` the benchmark, the tracking figures and the latency rows; `cargo xtask \
         metrics` the loop quality; `cargo xtask book` \
         writes this page from what they recorded (`target/figures.json`). Each table \
         says which command recorded it, and on which commit.\n",
    );
    let mut recorded = Vec::new();
    for (title, keys, how) in SECTIONS {
        let _ = write!(out, "\n## {title}\n");
        let tables: Vec<&Table> = (keys.iter())
            .flat_map(|key| figures.iter().filter(move |(k, _)| k.starts_with(key)))
            .map(|(_, table)| table)
            .collect();
        if tables.is_empty() {
            let _ = write!(out, "\nNot measured yet: {how}.\n");
            continue;
        }
        recorded.push(title);
        for table in tables {
            let on = table
                .commit
                .as_ref()
                .map_or_else(String::new, |c| format!(" on `{c}`"));
            let _ = write!(
                out,
                "\n{} Recorded by `{}`{on}.\n\n",
                table.intro, table.command
            );
            let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
            out.push_str(&line(&table.header));
            out.push_str(&line(&vec!["---".to_owned(); table.header.len()]));
            for row in &table.rows {
                out.push_str(&line(row));
            }
        }
    }
    (out, recorded)
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
        let path = dir.path().join("figures.json");
        let table = |value: &str| Table {
            command: "cargo xtask test".into(),
            intro: "Sizes.".into(),
            header: vec!["image".into(), "flash".into()],
            rows: vec![vec!["pico".into(), value.into()]],
            ..Table::default()
        };
        update_at(&path, "image pico", table("100 B")).unwrap();
        update_at(&path, "qemu", table("7")).unwrap();
        update_at(&path, "image pico", table("200 B")).unwrap();
        let figures = load(&path).unwrap();
        assert_eq!(figures.len(), 2);
        let (page, recorded) = render(&figures);
        assert_eq!(recorded, ["Memory", "Idle loop sets"]);
        assert!(page.contains("## Memory\n\nSizes. Recorded by `cargo xtask test`.\n\n"));
        assert!(page.contains("| image | flash |\n| --- | --- |\n| pico | 200 B |\n"));
        assert!(!page.contains("100 B"));
        assert!(page.contains("## Loop quality\n\nNot measured yet: run `cargo xtask metrics`"));
        // A file of another shape is started afresh, not kept half-read.
        std::fs::write(&path, "{\"images\": 3}").unwrap();
        assert!(load(&path).is_err());
        update_at(&path, "qemu", table("8")).unwrap();
        assert_eq!(load(&path).unwrap().len(), 1);
    }
}
