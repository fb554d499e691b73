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

/// A package of the repository that builds firmware images. Each has its own
/// workspace, memory map (`memory.x`) and target directory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Package {
    /// The root package `idle-head`: the core library and the Pico image.
    Root,
    /// `qemu/`, the package `idle-head-qemu`: the QEMU `lm3s6965evb` images.
    Qemu,
}

impl Package {
    /// Cargo arguments that select the package from the repository root
    /// (where cargo is run, so the root `.cargo/config.toml` applies).
    pub fn manifest_args(self) -> &'static [&'static str] {
        match self {
            Self::Root => &[],
            Self::Qemu => &["--manifest-path", "qemu/Cargo.toml"],
        }
    }
}

/// A board image of the firmware: one `[[bin]]` of one of the packages.
#[derive(Debug, Clone, Copy)]
pub struct Image {
    /// The package the image belongs to.
    pub package: Package,
    /// Bin target name, also the ELF file name.
    pub bin: &'static str,
}

/// The Raspberry Pi Pico image: the default features, so plain `cargo build --release`.
pub const PICO: Image = Image {
    package: Package::Root,
    bin: "pico",
};

/// The QEMU `lm3s6965evb` smoke image (`qemu/src/main.rs`).
pub const QEMU: Image = Image::qemu("qemu");

impl Image {
    /// Bin `bin` of the QEMU package.
    pub const fn qemu(bin: &'static str) -> Self {
        Self {
            package: Package::Qemu,
            bin,
        }
    }

    /// Release ELF of this image in its package's target directory.
    pub fn elf(&self, metadata: &Metadata) -> PathBuf {
        metadata
            .target_dir(self.package)
            .join(TARGET)
            .join("release")
            .join(self.bin)
    }

    /// `cargo build --release` for this image, run in the repository root,
    /// with the project's defmt level. The Pico image is the root package's
    /// only bin, so its command is the one users type.
    pub fn build(&self, root: &Path) -> Result<()> {
        let mut cargo = cargo(root);
        cargo
            .args(["build", "--release"])
            .args(self.package.manifest_args());
        if self.package != Package::Root {
            cargo.args(["--bin", self.bin]);
        }
        cargo.env("DEFMT_LOG", DEFMT_LOG);
        run(&mut cargo)
    }
}

/// The parts of `cargo metadata` this crate uses.
#[derive(Debug)]
pub struct Metadata {
    /// Where cargo puts build output for the root package.
    pub target_dir: PathBuf,
    /// Where cargo puts build output for the QEMU package (`qemu/target`
    /// unless configured otherwise).
    pub qemu_target_dir: PathBuf,
    /// Whether the core library's doc tests are switched on (`[lib] doctest`).
    pub lib_doctests: bool,
}

impl Metadata {
    /// The target directory of `package`.
    pub fn target_dir(&self, package: Package) -> &Path {
        match package {
            Package::Root => &self.target_dir,
            Package::Qemu => &self.qemu_target_dir,
        }
    }
}

/// Reads `cargo metadata` for both packages (no dependency resolution).
pub fn metadata(root: &Path) -> Result<Metadata> {
    let json = cargo_metadata(root, Package::Root)?;
    let target_dir = target_directory(&json)?;
    let qemu_target_dir = target_directory(&cargo_metadata(root, Package::Qemu)?)?;
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
        qemu_target_dir,
        lib_doctests,
    })
}

/// `cargo metadata --no-deps` of `package`, run in the repository root.
fn cargo_metadata(root: &Path, package: Package) -> Result<serde_json::Value> {
    let output = cargo(root)
        .args(["metadata", "--no-deps", "--format-version", "1"])
        .args(package.manifest_args())
        .output()
        .context("running `cargo metadata`")?;
    if !output.status.success() {
        bail!(
            "`cargo metadata` failed:\n{}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
    serde_json::from_slice(&output.stdout).context("parsing `cargo metadata` output")
}

fn target_directory(json: &serde_json::Value) -> Result<PathBuf> {
    Ok(json["target_directory"]
        .as_str()
        .context("`cargo metadata` gave no target_directory")?
        .into())
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
