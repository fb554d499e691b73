//! The book's link check: every relative link of the rendered book, and of
//! the README, must reach a file and, with an `#anchor`, an `id` in it.
//!
//! mdBook checks none of this. The check reads the HTML that mdBook wrote
//! rather than the Markdown, so an anchor is checked against the `id` that
//! mdBook actually gave a heading (its own rules for turning a title into
//! an id, with `-1`, `-2` for repeats), not against a guess at them. The
//! pages are read with `html5gum`, a WHATWG-compliant HTML tokenizer:
//! `id`, `href` and `src` are attributes of start tags, so no tree and no
//! CSS selectors are needed, and it has no dependencies. The README is
//! Markdown that GitHub renders: its links are read with `pulldown-cmark`
//! (the `CommonMark` parser mdBook itself uses), and an anchor into a book
//! page is checked against that page's rendered ids.

use std::{
    collections::{BTreeMap, BTreeSet},
    path::{Component, Path, PathBuf},
};

use anyhow::{Context, Result};
use html5gum::{DefaultEmitter, Token, Tokenizer};
use percent_encoding::percent_decode_str;
use pulldown_cmark::{Event, Parser, Tag};

/// A link that does not resolve.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Broken {
    /// The page it is on, relative to the book (or the repository, for the README).
    pub page: PathBuf,
    /// The link as written.
    pub link: String,
    /// Why it does not resolve.
    pub why: String,
}

impl std::fmt::Display for Broken {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: `{}`: {}", self.page.display(), self.link, self.why)
    }
}

/// What one HTML page holds: its ids and its links.
#[derive(Debug, Default)]
struct Page {
    ids: BTreeSet<String>,
    links: Vec<String>,
}

/// Reads the ids of `html` (`id`, and `name` of `<a>`) and its links
/// (`href` of `<a>`, `src` of `<img>`).
fn read_page(html: &str) -> Page {
    let mut emitter = DefaultEmitter::default();
    // Script and style contents are text, not tags.
    emitter.naively_switch_states(true);
    let mut page = Page::default();
    for token in Tokenizer::new_with_emitter(html, emitter).flatten() {
        let Token::StartTag(tag) = token else {
            continue;
        };
        let attribute = |name: &str| {
            tag.attributes
                .get(name.as_bytes())
                .map(|value| String::from_utf8_lossy(value).into_owned())
        };
        if let Some(id) = attribute("id") {
            page.ids.insert(id);
        }
        let link = match tag.name.as_slice() {
            b"a" => {
                if let Some(name) = attribute("name") {
                    page.ids.insert(name);
                }
                attribute("href")
            }
            b"img" => attribute("src"),
            _ => None,
        };
        page.links.extend(link);
    }
    page
}

/// Whether `link` leaves the site: it has a scheme (`https:`, `mailto:`)
/// or is protocol-relative (`//host`).
fn is_external(link: &str) -> bool {
    if link.starts_with("//") {
        return true;
    }
    let scheme = link.split(':').next().unwrap_or_default();
    link.contains(':')
        && !scheme.is_empty()
        && scheme.starts_with(|c: char| c.is_ascii_alphabetic())
        && scheme
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
}

/// `base/path` with `.` and `..` worked out, without touching the file
/// system; `None` if it climbs above the start of `base`.
fn join(base: &Path, path: &str) -> Option<PathBuf> {
    let mut out = Vec::new();
    for component in base.join(path).components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop()?;
            }
            Component::Normal(part) => out.push(part.to_owned()),
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(out.iter().collect())
}

/// A relative link split into its decoded path and anchor.
fn split(link: &str) -> (String, Option<String>) {
    let (path, anchor) = match link.split_once('#') {
        Some((path, anchor)) => (path, Some(anchor)),
        None => (link, None),
    };
    let path = path.split('?').next().unwrap_or_default();
    let decode = |s: &str| percent_decode_str(s).decode_utf8_lossy().into_owned();
    (decode(path), anchor.map(decode))
}

/// The rendered book in `book`: every HTML file, read once.
pub struct Book {
    root: PathBuf,
    pages: BTreeMap<PathBuf, Page>,
}

impl Book {
    /// Reads every `.html` file under `root`.
    pub fn read(root: &Path) -> Result<Self> {
        let mut pages = BTreeMap::new();
        let mut dirs = vec![root.to_path_buf()];
        while let Some(dir) = dirs.pop() {
            for entry in
                std::fs::read_dir(&dir).with_context(|| format!("reading {}", dir.display()))?
            {
                let path = entry?.path();
                if path.is_dir() {
                    dirs.push(path);
                } else if path.extension().is_some_and(|e| e == "html") {
                    let html = std::fs::read_to_string(&path)
                        .with_context(|| format!("reading {}", path.display()))?;
                    let relative = path.strip_prefix(root).unwrap_or(&path).to_path_buf();
                    pages.insert(relative, read_page(&html));
                }
            }
        }
        Ok(Self {
            root: root.to_path_buf(),
            pages,
        })
    }

    /// Pages read.
    pub fn pages(&self) -> usize {
        self.pages.len()
    }

    /// Whether `anchor` is an id of the page at `path` (relative to the
    /// book); the reason if not.
    fn has_anchor(&self, path: &Path, anchor: &str) -> Result<(), String> {
        match self.pages.get(path) {
            Some(page) if page.ids.contains(anchor) => Ok(()),
            Some(_) => Err(format!("no `#{anchor}` in {}", path.display())),
            None => Err(format!(
                "`#{anchor}`: {} is not a page of the book",
                path.display()
            )),
        }
    }

    /// Checks every relative link of every page; returns the number of
    /// links checked and the broken ones.
    pub fn check(&self) -> (usize, Vec<Broken>) {
        let mut checked = 0;
        let mut broken = Vec::new();
        for (path, page) in &self.pages {
            // mdBook's 404 page links through the site's absolute root.
            if path == Path::new("404.html") {
                continue;
            }
            let dir = path.parent().unwrap_or(Path::new(""));
            for link in page.links.iter().filter(|link| !is_external(link)) {
                checked += 1;
                if let Err(why) = self.resolve(path, dir, link) {
                    broken.push(Broken {
                        page: path.clone(),
                        link: link.clone(),
                        why,
                    });
                }
            }
        }
        (checked, broken)
    }

    fn resolve(&self, page: &Path, dir: &Path, link: &str) -> Result<(), String> {
        let (path, anchor) = split(link);
        let target = if path.is_empty() {
            page.to_path_buf()
        } else {
            let mut target = join(dir, &path).ok_or("leaves the book")?;
            if path.ends_with('/') || self.root.join(&target).is_dir() {
                target.push("index.html");
            }
            if !self.root.join(&target).is_file() {
                return Err(format!("no file {}", target.display()));
            }
            target
        };
        match anchor {
            Some(anchor) if !anchor.is_empty() => self.has_anchor(&target, &anchor),
            _ => Ok(()),
        }
    }
}

/// Checks the relative links of the Markdown file `readme` (in the
/// repository at `repo`): each must reach a file or folder of the
/// repository, and an anchor must point into a page of the book (a `.md`
/// file under `docs/`, rendered in `book`) and be one of its ids. Returns
/// the number of links checked and the broken ones.
pub fn check_readme(repo: &Path, readme: &str, name: &Path, book: &Book) -> (usize, Vec<Broken>) {
    let mut checked = 0;
    let mut broken = Vec::new();
    for event in Parser::new(readme) {
        let Event::Start(Tag::Link { dest_url, .. } | Tag::Image { dest_url, .. }) = event else {
            continue;
        };
        let link = dest_url.to_string();
        if is_external(&link) {
            continue;
        }
        checked += 1;
        if let Err(why) = resolve_readme_link(repo, &link, book) {
            broken.push(Broken {
                page: name.to_path_buf(),
                link,
                why,
            });
        }
    }
    (checked, broken)
}

fn resolve_readme_link(repo: &Path, link: &str, book: &Book) -> Result<(), String> {
    let (path, anchor) = split(link);
    if path.is_empty() {
        return Err(
            "an anchor in the README itself is not checked: link to a page of the book instead"
                .to_owned(),
        );
    }
    let target = join(Path::new(""), &path).ok_or("leaves the repository")?;
    if !repo.join(&target).exists() {
        return Err(format!("no file {}", target.display()));
    }
    let Some(anchor) = anchor.filter(|a| !a.is_empty()) else {
        return Ok(());
    };
    let page = target
        .strip_prefix("docs")
        .ok()
        .filter(|page| page.extension().is_some_and(|e| e == "md"))
        .ok_or_else(|| {
            format!(
                "`#{anchor}`: anchors are checked only in the book's pages (docs/**/*.md), \
                 not in {}",
                target.display()
            )
        })?;
    book.has_anchor(&page.with_extension("html"), &anchor)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A book of two pages in a fresh folder.
    fn book(pages: &[(&str, &str)]) -> (PathBuf, Book) {
        let dir =
            std::env::temp_dir().join(format!("book-links-{}-{}", std::process::id(), pages.len()));
        let _ = std::fs::remove_dir_all(&dir);
        for (path, html) in pages {
            let path = dir.join(path);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, html).unwrap();
        }
        let book = Book::read(&dir).unwrap();
        (dir, book)
    }

    #[test]
    fn reads_ids_and_links_but_not_inside_scripts() {
        let page = read_page(
            r##"<h2 id="over-usb"><a class="header" href="#over-usb">Over USB</a></h2>
               <script>const s = '<a href="nowhere.html">';</script>
               <img src="../preview.png"><a name="old"></a><a href="https://x.org/a">x</a>"##,
        );
        assert_eq!(
            page.ids.iter().map(String::as_str).collect::<Vec<_>>(),
            ["old", "over-usb"]
        );
        assert_eq!(
            page.links,
            ["#over-usb", "../preview.png", "https://x.org/a"]
        );
    }

    #[test]
    fn links_and_anchors_must_resolve() {
        let (dir, book) = book(&[
            (
                "user/console.html",
                r##"<h1 id="talking">T</h1>
                    <a href="#talking">ok</a>
                    <a href="../dev/tests.html#no-panic">ok</a>
                    <a href="../dev/tests.html">ok</a>
                    <a href="../dev/">ok: the folder's index</a>
                    <a href="#gone">same page, no such id</a>
                    <a href="../dev/tests.html#gone">other page, no such id</a>
                    <a href="flashing.html">no such page</a>
                    <a href="../../outside.html">leaves the book</a>
                    <a href="mailto:a@b.c">external</a>
                    <a href="https://example.org/x.html">external</a>"##,
            ),
            ("dev/tests.html", r#"<h3 id="no-panic">N</h3>"#),
            ("dev/index.html", ""),
            ("404.html", r#"<a href="/nowhere.html">skipped</a>"#),
        ]);
        let (checked, broken) = book.check();
        assert_eq!(checked, 8);
        let links: Vec<&str> = broken.iter().map(|b| b.link.as_str()).collect();
        assert_eq!(
            links,
            [
                "#gone",
                "../dev/tests.html#gone",
                "flashing.html",
                "../../outside.html"
            ]
        );
        assert!(
            broken[1].why.contains("no `#gone` in dev/tests.html"),
            "{}",
            broken[1]
        );
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn the_readme_links_into_the_book() {
        let (dir, book) = book(&[("user/hardware.html", r#"<h2 id="servos">S</h2>"#)]);
        let repo = dir.join("repo");
        std::fs::create_dir_all(repo.join("docs/user")).unwrap();
        std::fs::write(repo.join("docs/user/hardware.md"), "").unwrap();
        std::fs::write(repo.join("docs/preview.png"), "").unwrap();
        let readme = "[w](docs/user/hardware.md#servos) ![p](docs/preview.png) \
                      [x](https://example.org) [a](docs/user/hardware.md#power) \
                      [b](docs/user/missing.md) [c](#quick-start) [d](docs/preview.png#top)";
        let (checked, broken) = check_readme(&repo, readme, Path::new("README.md"), &book);
        assert_eq!(checked, 6);
        let links: Vec<&str> = broken.iter().map(|b| b.link.as_str()).collect();
        assert_eq!(
            links,
            [
                "docs/user/hardware.md#power",
                "docs/user/missing.md",
                "#quick-start",
                "docs/preview.png#top"
            ]
        );
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn external_links_are_told_apart() {
        for link in ["https://a.b", "mailto:x@y", "//cdn.x/y.js", "HTTP://A"] {
            assert!(is_external(link), "{link}");
        }
        for link in ["a.html", "../a.html#b:c", "#x", "a:b/c.html"] {
            // `a:b/c.html` has a scheme by the URL rules; the others do not.
            assert_eq!(is_external(link), link == "a:b/c.html", "{link}");
        }
    }
}
