//! Installs what the commands need and is missing.

use std::{
    path::Path,
    process::{Command, Stdio},
};

use anyhow::{Context, Result, bail};

use crate::project::{self, TARGET};

/// QEMU's system emulator for Arm, and the Debian/Ubuntu package that has it.
pub const QEMU_BINARY: &str = "qemu-system-arm";
const QEMU_PACKAGE: &str = "qemu-system-arm";

/// Rustup components the checks use.
const COMPONENTS: [&str; 2] = ["rustfmt", "clippy"];

/// Adds the firmware target, rustfmt and clippy to the toolchain the
/// repository uses (the one named by `rust-toolchain.toml`, so rustup runs in
/// the repository root).
pub fn ensure_toolchain(root: &Path) -> Result<()> {
    let Some(targets) = rustup_installed(root, "target") else {
        // No rustup: a toolchain installed some other way must bring these
        // itself; the build says so if it does not.
        return Ok(());
    };
    if !targets.iter().any(|target| target == TARGET) {
        project::run(
            Command::new("rustup")
                .args(["target", "add", TARGET])
                .current_dir(root),
        )?;
    }
    let components = rustup_installed(root, "component").unwrap_or_default();
    let missing: Vec<&str> = COMPONENTS
        .into_iter()
        .filter(|name| {
            !components
                .iter()
                .any(|component| component.split('-').next() == Some(name))
        })
        .collect();
    if !missing.is_empty() {
        project::run(
            Command::new("rustup")
                .args(["component", "add"])
                .args(&missing)
                .current_dir(root),
        )?;
    }
    Ok(())
}

/// `rustup <what> list --installed`, one name a line.
fn rustup_installed(root: &Path, what: &str) -> Option<Vec<String>> {
    let output = Command::new("rustup")
        .args([what, "list", "--installed"])
        .current_dir(root)
        .stderr(Stdio::inherit())
        .output()
        .ok()?;
    output.status.success().then(|| {
        String::from_utf8_lossy(&output.stdout)
            .lines()
            .map(|line| line.trim().to_owned())
            .collect()
    })
}

/// Makes sure `qemu-system-arm` runs; installs it with apt-get when running as
/// root on Debian or Ubuntu, and otherwise says which package to install.
pub fn ensure_qemu() -> Result<()> {
    if qemu_version().is_some() {
        return Ok(());
    }
    let apt = Path::new("/etc/debian_version").exists()
        && Command::new("apt-get")
            .arg("--version")
            .stdout(Stdio::null())
            .status()
            .is_ok_and(|status| status.success());
    if !apt {
        bail!(
            "`{QEMU_BINARY}` was not found; install QEMU's Arm system emulator \
             (package `{QEMU_PACKAGE}` on Debian/Ubuntu, `qemu-system-arm` on Fedora, \
             `qemu` on Homebrew) and run the command again"
        );
    }
    if !is_root() {
        bail!(
            "`{QEMU_BINARY}` was not found; install it with \
             `sudo apt-get install {QEMU_PACKAGE}` and run the command again"
        );
    }
    println!("{QEMU_BINARY} is missing: installing the `{QEMU_PACKAGE}` package");
    project::run(
        Command::new("apt-get")
            .args(["update", "-q"])
            .env("DEBIAN_FRONTEND", "noninteractive"),
    )?;
    project::run(
        Command::new("apt-get")
            .args([
                "install",
                "-y",
                "-q",
                "--no-install-recommends",
                QEMU_PACKAGE,
            ])
            .env("DEBIAN_FRONTEND", "noninteractive"),
    )?;
    qemu_version()
        .map(|_| ())
        .with_context(|| format!("`{QEMU_BINARY}` still does not run after installing it"))
}

/// First line of `qemu-system-arm --version`, if it runs.
pub fn qemu_version() -> Option<String> {
    let output = Command::new(QEMU_BINARY)
        .arg("--version")
        .stdin(Stdio::null())
        .output()
        .ok()?;
    output.status.success().then(|| {
        String::from_utf8_lossy(&output.stdout)
            .lines()
            .next()
            .unwrap_or_default()
            .to_owned()
    })
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|output| output.status.success() && output.stdout.trim_ascii() == b"0")
}
