//! `cargo xtask panel`: the browser control panel (`panel/`) served on
//! localhost and bridged to a head, or exported for any static host.

mod bridge;
pub mod browser;
mod server;

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::mpsc;

use anyhow::{Context, Result};

use crate::{project, setup};

pub use bridge::Bridge;

/// `cargo xtask panel` options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Bridge the page to the shipped Pico image running in the RP2040
    /// emulator at real time, over its USB serial port: a head without a
    /// board.
    #[arg(long, conflicts_with_all = ["qemu", "port", "export"])]
    pub sim: bool,
    /// Bridge the page to the QEMU image (a clean head at real time) over
    /// its UART0.
    #[arg(long, conflicts_with_all = ["port", "export"])]
    pub qemu: bool,
    /// Bridge the page to a board's serial port (115200 8N1), e.g.
    /// /dev/ttyACM0.
    #[arg(long, value_name = "dev", conflicts_with = "export")]
    pub port: Option<PathBuf>,
    /// Where to serve the page.
    #[arg(long, value_name = "addr:port", default_value = "127.0.0.1:8080")]
    pub listen: SocketAddr,
    /// Write a self-contained copy of the page (dependencies included) to
    /// this folder, for any static host, instead of serving it.
    #[arg(long, value_name = "dir")]
    pub export: Option<PathBuf>,
    /// Run the panel's browser tests (the stage of `cargo xtask test`)
    /// instead: headless Chromium over Web Serial, the bridge and a serial
    /// port.
    #[arg(long, conflicts_with_all = ["sim", "qemu", "port", "export"])]
    pub test: bool,
}

pub fn command(args: &Args) -> Result<bool> {
    let root = project::root();
    if args.test {
        let (root, metadata) = setup::prepare()?;
        browser::stage(&root, &metadata)?;
        return Ok(true);
    }
    ensure_dependencies(&root)?;
    if let Some(dir) = &args.export {
        export(&root, dir)?;
        println!("panel: exported to {}", dir.display());
        return Ok(true);
    }
    let bridge = if args.sim {
        let (root, metadata) = setup::prepare()?;
        project::PICO.build(&root)?;
        Some(Bridge::sim(&root, &project::PICO.elf(&metadata))?)
    } else if args.qemu {
        let (root, metadata) = setup::prepare()?;
        setup::ensure_qemu()?;
        project::QEMU.build(&root)?;
        Some(Bridge::qemu(&project::QEMU.elf(&metadata))?)
    } else if let Some(port) = &args.port {
        Some(Bridge::port(port)?)
    } else {
        None
    };
    let (stop_tx, stop_rx) = mpsc::channel();
    let ctrlc_tx = stop_tx.clone();
    ctrlc::set_handler(move || {
        let _ = ctrlc_tx.send("interrupted".to_owned());
    })
    .context("setting the Ctrl-C handler")?;
    let name = bridge.as_ref().map(|b| b.name.clone());
    let server = server::Server::start(&root, args.listen, bridge, stop_tx)?;
    println!("panel: http://{}/", server.address);
    match name {
        Some(name) => eprintln!(
            "panel: bridged to {name}; open the address in a browser (Ctrl-C stops everything)"
        ),
        None => eprintln!(
            "panel: no bridge; open the address in Chromium, Edge or Opera and press Connect \
             to choose the head's serial port (Web Serial)"
        ),
    }
    let why = stop_rx.recv().unwrap_or_else(|_| "stopped".to_owned());
    eprintln!("panel: {why}; stopping");
    drop(server);
    Ok(true)
}

/// The content type of `file` if it is of a kind the page is made of:
/// what the server serves from `panel/` and what `--export` copies.
pub fn content_type(file: &Path) -> Option<&'static str> {
    Some(match file.extension()?.to_str()? {
        "html" => "text/html; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "js" => "text/javascript; charset=utf-8",
        "svg" => "image/svg+xml",
        "png" => "image/png",
        _ => return None,
    })
}

/// The files of the page in `panel/` (not its tests or package files),
/// relative to it.
pub fn page_files(root: &Path) -> Result<Vec<PathBuf>> {
    let dir = root.join("panel");
    let mut files = Vec::new();
    for entry in std::fs::read_dir(&dir).with_context(|| format!("reading {}", dir.display()))? {
        let entry = entry?;
        let name = PathBuf::from(entry.file_name());
        if content_type(&name).is_some() && entry.file_type()?.is_file() {
            files.push(name);
        }
    }
    files.sort();
    Ok(files)
}

/// The dependencies' files the page loads, as `(URL path under vendor/,
/// file in node_modules)`.
pub const VENDOR: [(&str, &str); 2] = [
    ("uplot/uPlot.iife.min.js", "uplot/dist/uPlot.iife.min.js"),
    ("uplot/uPlot.min.css", "uplot/dist/uPlot.min.css"),
];

fn export(root: &Path, dir: &Path) -> Result<()> {
    let panel = root.join("panel");
    std::fs::create_dir_all(dir.join("vendor/uplot"))
        .with_context(|| format!("creating {}", dir.display()))?;
    std::fs::write(dir.join("bridge.json"), server::NO_BRIDGE)?;
    let page = page_files(root)?
        .into_iter()
        .map(|f| (panel.join(&f), dir.join(f)));
    let vendor = VENDOR.map(|(url, file)| {
        let from = panel.join("node_modules").join(file);
        (from, dir.join("vendor").join(url))
    });
    for (from, to) in page.chain(vendor) {
        std::fs::copy(&from, to).with_context(|| format!("copying {}", from.display()))?;
    }
    Ok(())
}

/// Makes sure the page's pinned npm packages are installed in
/// `panel/node_modules` (Playwright's browser download off: the tests use
/// the system's Chromium).
pub fn ensure_dependencies(root: &Path) -> Result<()> {
    let env = [("PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD", "1")];
    crate::sim::node::npm_ci(&root.join("panel"), &["uplot", "playwright-core"], &env)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_is_its_html_css_scripts_and_pictures() {
        for (file, kind) in [
            ("index.html", "text/html; charset=utf-8"),
            ("panel.js", "text/javascript; charset=utf-8"),
            ("panel.css", "text/css; charset=utf-8"),
            ("head.svg", "image/svg+xml"),
            ("head.png", "image/png"),
        ] {
            assert_eq!(content_type(Path::new(file)), Some(kind), "{file}");
        }
        for file in "package.json|package-lock.json|browser.mjs|tests|.html".split('|') {
            assert_eq!(content_type(Path::new(file)), None, "{file}");
        }
        let files = page_files(&project::root()).unwrap();
        assert!(files.contains(&PathBuf::from("index.html")), "{files:?}");
        assert!(files.iter().all(|f| content_type(f).is_some()), "{files:?}");
    }
}
