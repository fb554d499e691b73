//! Installs what the commands need and is missing.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};
use xshell::{Shell, cmd};

use crate::{board::PICO2_TARGET, project};

pub const QEMU_BINARY: &str = "qemu-system-arm";

/// What a command that builds starts from: the firmware targets, rustfmt
/// and clippy added with rustup (if any); the repository root, its metadata.
pub fn prepare() -> Result<(PathBuf, project::Metadata)> {
    let sh = project::shell(".")?;
    for (what, wanted) in [
        ("target", [project::TARGET, PICO2_TARGET]),
        ("component", ["rustfmt", "clippy"]),
    ] {
        let Ok(list) = cmd!(sh, "rustup {what} list --installed").quiet().read() else {
            break;
        };
        // Components are listed with their host (`clippy-x86_64-…`).
        let installed = |name: &&str| {
            list.lines()
                .any(|l| l.trim() == *name || l.trim().split('-').next() == Some(name))
        };
        let missing: Vec<&str> = wanted.into_iter().filter(|name| !installed(name)).collect();
        if !missing.is_empty() {
            project::run(&sh, &[], cmd!(sh, "rustup {what} add {missing...}"))?;
        }
    }
    let root = project::root();
    Ok((root.clone(), project::metadata(&root)?))
}

pub fn ensure_qemu() -> Result<()> {
    ensure_program(
        QEMU_BINARY,
        &["qemu-system-arm"],
        "QEMU's Arm system emulator (package `qemu-system-arm` on Debian, Ubuntu and Fedora, \
         `qemu` on Homebrew)",
    )
}

/// Makes sure `program` runs: else installs `packages` with apt-get as
/// root on Debian or Ubuntu, or says to install `what`.
pub fn ensure_program(program: &str, packages: &[&str], what: &str) -> Result<()> {
    if version(program).is_some() {
        return Ok(());
    }
    let list = packages.join(" ");
    if !Path::new("/etc/debian_version").exists() || version("apt-get").is_none() {
        bail!("`{program}` was not found; install {what} and run the command again");
    }
    let sh = project::shell(".")?;
    ensure!(
        cmd!(sh, "id -u").quiet().read().ok().as_deref() == Some("0"),
        "`{program}` was not found; install it with `sudo apt-get install {list}` and run the command again"
    );
    println!("{program} is missing: installing {list}");
    let apt_get = |cmd| project::run(&sh, &[("DEBIAN_FRONTEND", "noninteractive")], cmd);
    apt_get(cmd!(sh, "apt-get update -q"))?;
    apt_get(cmd!(
        sh,
        "apt-get install -y -q --no-install-recommends {packages...}"
    ))?;
    let ran = version(program).map(|_| ());
    ran.with_context(|| format!("`{program}` still does not run after installing {list}"))
}

/// First line of `<program> --version`, if it runs.
pub fn version(program: impl AsRef<Path>) -> Option<String> {
    let sh = Shell::new().ok()?;
    let version = cmd!(sh, "{program} --version");
    let text = version.quiet().ignore_stderr().read().ok()?;
    Some(text.lines().next().unwrap_or_default().trim().to_owned())
}

/// The mdBook release the book is built with: pinned, as the ids the link
/// check reads may change between releases.
pub const MDBOOK_VERSION: &str = "0.5.4";

/// The pinned `mdbook`: on the `PATH` or in `tools`, else installed there
/// with `cargo install` (HTML and search only: no `serve` or `watch`).
pub fn ensure_mdbook(tools: &Path) -> Result<PathBuf> {
    let wanted = format!("mdbook v{MDBOOK_VERSION}");
    let local = tools.join("bin").join("mdbook");
    let pinned = |program: &PathBuf| version(program).as_deref() == Some(wanted.as_str());
    if let Some(program) = [local.clone(), PathBuf::from("mdbook")]
        .into_iter()
        .find(pinned)
    {
        return Ok(program);
    }
    let tools_dir = project::relative(tools);
    let tools_dir = tools_dir.display();
    println!("installing {wanted} into {tools_dir} (a minute or so, once)");
    let sh = project::shell(".")?;
    // `host-tuple`: a host program, whatever .cargo/config.toml builds for.
    let build_dir = tools.join("build");
    let install = cmd!(
        sh,
        "cargo install mdbook --locked --version {MDBOOK_VERSION} --no-default-features --features search --target host-tuple --target-dir {build_dir} --root {tools}"
    );
    // Unoptimised: it compiles in half the time, and the book still builds
    // in under a second.
    let quick = [
        ("CARGO_PROFILE_RELEASE_OPT_LEVEL", "0"),
        ("CARGO_PROFILE_RELEASE_DEBUG", "false"),
    ];
    project::run(&sh, &quick, install)?;
    ensure!(
        pinned(&local),
        "installed {wanted}, but {} does not run as it",
        local.display()
    );
    Ok(local)
}
