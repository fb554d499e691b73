//! `cargo xtask book`: the book built with mdBook into `target/book`, and
//! every link in it checked.
//!
//! The links are checked by linkinator (npm, pinned in `xtask/book/`; it
//! installs in seconds where a Rust link checker compiles for minutes): in
//! the built book every page, picture and `#anchor` (against the ids mdBook
//! gave its headings, the measured figures page included), and in the
//! README every file of the repository and `#anchor` (against the heading
//! ids GitHub gives the Markdown). Links to other sites are not followed.

use std::path::Path;

use anyhow::Result;
use xshell::cmd;

use crate::{project, setup, sim::node};

/// The stage's name in `cargo xtask test`.
pub const STAGE: &str = "book: built with mdBook into target/book, every link and anchor resolves";

/// Where the book is built, as `docs/book.toml`'s `build-dir` also says.
const OUT: &str = "target/book";
/// Links not followed: to any other site than linkinator's own server.
const EXTERNAL: &str = "^https?://(?!localhost)";

/// Builds the book and checks its links and the README's; fails on a
/// build error or a broken link.
pub fn stage(root: &Path) -> Result<()> {
    let mdbook = setup::ensure_mdbook(&root.join("target").join("tools"))?;
    let tools = root.join("xtask/book");
    node::npm_ci(&tools, &["linkinator"], &[])?;
    let linkinator = tools.join("node_modules/.bin/linkinator");
    let sh = project::shell(".")?;
    project::run(&sh, &[], cmd!(sh, "{mdbook} build docs --dest-dir {OUT}"))?;
    let check = ["--check-fragments", "--verbosity", "error", "--skip"];
    project::run(
        &sh,
        &[],
        cmd!(sh, "{linkinator} {OUT} --recurse {check...} {EXTERNAL}"),
    )?;
    project::run(
        &sh,
        &[],
        cmd!(
            sh,
            "{linkinator} README.md --markdown {check...} {EXTERNAL}"
        ),
    )?;
    println!("every link resolves; open {OUT}/index.html");
    Ok(())
}

/// `cargo xtask book`. `Ok(false)` when the build or the link check failed.
pub fn command() -> Result<bool> {
    let (root, _) = setup::prepare()?;
    match stage(&root) {
        Ok(()) => Ok(true),
        Err(error) => {
            println!("book FAILED: {error:#}");
            Ok(false)
        }
    }
}
