//! Where things are in the repository and how the firmware images are built.

use std::{
    ffi::OsStr,
    fmt::Write as _,
    path::{Path, PathBuf},
    process::Command,
};

use anyhow::{Context, Result, bail};

/// The firmware's compilation target (ARMv6-M: RP2040's Cortex-M0+, QEMU's Cortex-M0).
pub const TARGET: &str = "thumbv6m-none-eabi";

/// The defmt log level the firmware images are built with (`DEFMT_LOG`). The
/// expected QEMU log on file is recorded at this level.
pub const DEFMT_LOG: &str = "info";

/// The repository root: the parent of this crate's directory.
pub fn root() -> PathBuf {
    let xtask = Path::new(env!("CARGO_MANIFEST_DIR"));
    xtask
        .parent()
        .expect("xtask/ lives inside the repository")
        .to_path_buf()
}

/// A board image of the firmware: one `[[bin]]` of the root package with its features.
#[derive(Debug, Clone, Copy)]
pub struct Image {
    /// Bin target name, also the ELF file name.
    pub bin: &'static str,
    /// Cargo arguments that select the image (features and bin).
    pub cargo_args: &'static [&'static str],
}

/// The Raspberry Pi Pico image: the default features, so plain `cargo build --release`.
pub const PICO: Image = Image {
    bin: "pico",
    cargo_args: &[],
};

/// The QEMU `lm3s6965evb` image.
pub const QEMU: Image = Image {
    bin: "qemu",
    cargo_args: &[
        "--no-default-features",
        "--features",
        "qemu",
        "--bin",
        "qemu",
    ],
};

impl Image {
    /// Release ELF of this image inside `target_dir`.
    pub fn elf(&self, target_dir: &Path) -> PathBuf {
        target_dir.join(TARGET).join("release").join(self.bin)
    }

    /// `cargo build --release` for this image, with the project's defmt level.
    pub fn build(&self, root: &Path) -> Result<()> {
        let mut cargo = cargo(root);
        cargo
            .args(["build", "--release"])
            .args(self.cargo_args)
            .env("DEFMT_LOG", DEFMT_LOG);
        run(&mut cargo)
    }
}

/// The parts of `cargo metadata` this crate uses.
#[derive(Debug)]
pub struct Metadata {
    /// Where cargo puts build output for the root package.
    pub target_dir: PathBuf,
    /// Whether the core library's doc tests are switched on (`[lib] doctest`).
    pub lib_doctests: bool,
}

/// Reads `cargo metadata` for the root package (no dependency resolution).
pub fn metadata(root: &Path) -> Result<Metadata> {
    let output = cargo(root)
        .args(["metadata", "--no-deps", "--format-version", "1"])
        .output()
        .context("running `cargo metadata`")?;
    if !output.status.success() {
        bail!(
            "`cargo metadata` failed:\n{}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
    let json: serde_json::Value =
        serde_json::from_slice(&output.stdout).context("parsing `cargo metadata` output")?;
    let target_dir = json["target_directory"]
        .as_str()
        .context("`cargo metadata` gave no target_directory")?
        .into();
    let lib_doctests = json["packages"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|package| package["name"] == "idle-head")
        .flat_map(|package| package["targets"].as_array().into_iter().flatten())
        .any(|target| {
            target["kind"]
                .as_array()
                .is_some_and(|kinds| kinds.iter().any(|kind| kind == "lib"))
                && target["doctest"] == true
        });
    Ok(Metadata {
        target_dir,
        lib_doctests,
    })
}

/// A `cargo` command running in `dir`.
pub fn cargo(dir: &Path) -> Command {
    let mut command = Command::new("cargo");
    command.current_dir(dir);
    command
}

/// Prints a command line the way a user would type it (relative to the root).
pub fn display(command: &Command) -> String {
    let mut line = String::new();
    let root = root();
    if let Some(dir) = command.get_current_dir()
        && dir != root
    {
        let dir = dir.strip_prefix(&root).unwrap_or(dir);
        let _ = write!(line, "(cd {} && ", dir.display());
    }
    for (key, value) in command.get_envs() {
        if let Some(value) = value {
            let _ = write!(
                line,
                "{}={} ",
                key.to_string_lossy(),
                value.to_string_lossy()
            );
        }
    }
    line.push_str(&command.get_program().to_string_lossy());
    for arg in command.get_args() {
        line.push(' ');
        line.push_str(&quote(arg));
    }
    if command.get_current_dir().is_some_and(|dir| dir != root) {
        line.push(')');
    }
    line
}

fn quote(arg: &OsStr) -> String {
    let arg = arg.to_string_lossy();
    if arg.is_empty() || arg.contains(|c: char| c.is_whitespace() || c == '\'') {
        format!("'{}'", arg.replace('\'', r"'\''"))
    } else {
        arg.into_owned()
    }
}

/// Echoes and runs a command with inherited output; fails unless it exits with 0.
pub fn run(command: &mut Command) -> Result<()> {
    let line = display(command);
    println!("$ {line}");
    let status = command
        .status()
        .with_context(|| format!("could not start `{line}`"))?;
    if !status.success() {
        bail!("`{line}` failed ({status})");
    }
    Ok(())
}
