//! `cargo xtask book`: the book built with mdBook into `target/book`, its
//! links and the README's checked by linkinator (pinned in `xtask/book/`),
//! anchors included; other sites are not followed.

use std::path::Path;

use anyhow::Result;
use xshell::cmd;

use crate::{project, setup, sim::node};

pub const STAGE: &str = "book: built with mdBook into target/book, every link and anchor resolves";

/// Where the book is built, as `docs/book.toml`'s `build-dir` also says.
const OUT: &str = "target/book";
/// Links not followed: to any other site than linkinator's own server.
const EXTERNAL: &str = "^https?://(?!localhost)";

pub fn stage(root: &Path) -> Result<()> {
    let mdbook = setup::ensure_mdbook(&root.join("target").join("tools"))?;
    let tools = root.join("xtask/book");
    node::npm_ci(&tools, &["linkinator"], &[])?;
    let linkinator = tools.join("node_modules/.bin/linkinator");
    let sh = project::shell(".")?;
    let run = |cmd| project::run(&sh, &[], cmd);
    run(cmd!(sh, "{mdbook} build docs --dest-dir {OUT}"))?;
    let check = ["--check-fragments", "--verbosity", "error", "--skip"];
    for target in [[OUT, "--recurse"], ["README.md", "--markdown"]] {
        run(cmd!(sh, "{linkinator} {target...} {check...} {EXTERNAL}"))?;
    }
    println!("every link resolves; open {OUT}/index.html");
    Ok(())
}

/// `cargo xtask book`. `Ok(false)` when the build or the link check failed.
pub fn command() -> Result<bool> {
    let (root, _) = setup::prepare()?;
    Ok(project::passed("book", &stage(&root)))
}
