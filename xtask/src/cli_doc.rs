//! `docs/dev/xtask.md` against the command line's definition: every
//! command clap knows has its line in the page, and every long option of
//! a command is named on a line of the page that names the command.

use clap::CommandFactory;

use crate::{cli::Cli, project};

/// Whether `line` names `word`, not a longer command or option.
fn names(line: &str, word: &str) -> bool {
    line.match_indices(word).any(|(at, _)| {
        let next = line[at + word.len()..].chars().next();
        !next.is_some_and(|c| c.is_ascii_alphanumeric() || c == '-')
    })
}

/// What the page misses of the definition: commands, then options.
fn missing(page: &str) -> Vec<String> {
    let mut missing = Vec::new();
    for command in Cli::command().get_subcommands() {
        let name = command.get_name();
        let named = format!("cargo xtask {name}");
        let lines: Vec<&str> = page.lines().filter(|l| names(l, &named)).collect();
        if lines.is_empty() {
            missing.push(format!("`cargo xtask {name}`"));
            continue;
        }
        for arg in command.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            if arg.is_hide_set() || long == "help" {
                continue;
            }
            let option = format!("--{long}");
            if !lines.iter().any(|line| names(line, &option)) {
                missing.push(format!("`cargo xtask {name} {option}`"));
            }
        }
    }
    missing
}

#[test]
fn the_page_names_every_command_and_option() {
    let path = project::root().join("docs/dev/xtask.md");
    let page = std::fs::read_to_string(&path).expect("docs/dev/xtask.md");
    let missing = missing(&page);
    assert!(
        missing.is_empty(),
        "docs/dev/xtask.md does not name {} (on a line with its command)",
        missing.join(", ")
    );
}

#[test]
fn a_command_or_option_left_out_is_named() {
    let page = "| `cargo xtask qemu --bless --timeout S` | |\n| `cargo xtask testing` |\n";
    let left_out = missing(page);
    assert!(!left_out.iter().any(|m| m.contains("qemu")), "{left_out:?}");
    assert!(left_out.contains(&"`cargo xtask test`".to_owned()));
    // An option named on another command's line does not count.
    let page = "`cargo xtask bench`\n`cargo xtask test --no-budget`\n";
    let left_out = missing(page);
    assert!(left_out.contains(&"`cargo xtask bench --no-budget`".to_owned()));
    assert!(!left_out.contains(&"`cargo xtask test --no-budget`".to_owned()));
}
