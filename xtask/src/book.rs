//! `cargo xtask book`: the measured figures page, the book built with
//! mdBook into `target/book`, and every link in it checked.

mod links;

use std::path::Path;

use anyhow::{Result, bail};
use xshell::cmd;

use crate::{figures, log::Run, project, setup};

/// The stage's name in `cargo xtask test`.
pub const STAGE: &str = "book: built with mdBook into target/book, every link and anchor resolves";

/// The book's sources (`docs/book.toml`, `docs/SUMMARY.md`, `docs/**/*.md`).
const DOCS: &str = "docs";
/// Where the book is built, as `docs/book.toml`'s `build-dir` also says.
const OUT: &str = "target/book";
/// The generated page of measured figures (ignored by git).
const FIGURES_PAGE: &str = "docs/design/figures.md";
/// The README, whose links into the book are checked too.
const README: &str = "README.md";

/// Records the QEMU smoke run's figures if `smoke` is given (`cargo xtask
/// test` passes its run), writes the figures page, builds the book and
/// checks its links; fails on a build error or a broken link.
pub fn stage(root: &Path, smoke: Option<&Run>) -> Result<()> {
    if let Some(run) = smoke {
        crate::qemu::record_figures(&run.log);
    }
    let recorded = figures::write_page(&figures::path(), &root.join(FIGURES_PAGE))?;
    if recorded.is_empty() {
        println!(
            "{FIGURES_PAGE}: no figures recorded yet (`cargo xtask test` and `cargo xtask \
             metrics` record them); the page says how to get them"
        );
    } else {
        println!(
            "{FIGURES_PAGE}: written from {} ({})",
            project::relative(&figures::path()).display(),
            recorded.join(", ")
        );
    }

    let mdbook = setup::ensure_mdbook(&root.join("target").join("tools"))?;
    let out = root.join(OUT);
    let sh = project::shell(".")?;
    project::run(&sh, &[], cmd!(sh, "{mdbook} build {DOCS} --dest-dir {out}"))?;

    let book = links::Book::read(&out)?;
    let (in_book, mut broken) = book.check();
    let readme = std::fs::read_to_string(root.join(README))?;
    let (in_readme, readme_broken) = links::check_readme(root, &readme, Path::new(README), &book);
    broken.extend(readme_broken);
    println!(
        "links: {in_book} relative links in {} pages of the book and {in_readme} in the README",
        book.pages()
    );
    if !broken.is_empty() {
        for link in &broken {
            println!("  broken: {link}");
        }
        bail!("{} broken link(s); the first: {}", broken.len(), broken[0]);
    }
    println!("every link resolves; open {OUT}/index.html");
    Ok(())
}

/// `cargo xtask book`. `Ok(false)` when the build or the link check failed.
pub fn command() -> Result<bool> {
    let root = project::root();
    setup::ensure_toolchain(&root)?;
    match stage(&root, None) {
        Ok(()) => Ok(true),
        Err(error) => {
            println!("book FAILED: {error:#}");
            Ok(false)
        }
    }
}
