//! Where things are in the repository, how commands run (the one process
//! runner: [`run`] to the end with inherited output, [`finish`] with its
//! output read as it comes and a time limit), and how the firmware images
//! are built.

use std::{
    fmt::Write as _,
    path::{Path, PathBuf},
    process::{Child, ChildStderr, ChildStdout},
    thread,
    time::Duration,
};

use anyhow::{Context, Result, anyhow};
use cargo_metadata::MetadataCommand;
use wait_timeout::ChildExt;
use xshell::{Cmd, Shell, cmd};

/// The firmware's compilation target (ARMv6-M: RP2040's Cortex-M0+, QEMU's Cortex-M0).
pub const TARGET: &str = "thumbv6m-none-eabi";

/// The defmt log level the firmware images are built with (`DEFMT_LOG`). The
/// expected QEMU log on file is recorded at this level.
pub const DEFMT_LOG: &str = "info";

/// The environment of every firmware build: the project's defmt level, over
/// whatever the caller's environment says.
pub const FIRMWARE_ENV: &[(&str, &str)] = &[("DEFMT_LOG", DEFMT_LOG)];

/// The repository root: the parent of this crate's directory. Commands run
/// from any folder of the repository, so every path starts here.
pub fn root() -> PathBuf {
    let xtask = Path::new(env!("CARGO_MANIFEST_DIR"));
    xtask
        .parent()
        .expect("xtask/ lives inside the repository")
        .to_path_buf()
}

/// `path` relative to the repository root, for messages.
pub fn relative(path: &Path) -> PathBuf {
    path.strip_prefix(root()).unwrap_or(path).to_path_buf()
}

/// A shell whose commands run in `dir`, relative to the repository root.
pub fn shell(dir: &str) -> Result<Shell> {
    let sh = Shell::new()?;
    sh.change_dir(root().join(dir));
    Ok(sh)
}

/// Echoes `cmd` the way a user would type it from the repository root
/// (`(cd dir && VAR=value program args)`), then runs it with `env` and
/// inherited output; fails unless it exits with 0.
pub fn run(sh: &Shell, env: &[(&str, &str)], cmd: Cmd<'_>) -> Result<()> {
    let mut line = String::new();
    for (key, value) in env {
        let _ = write!(line, "{key}={value} ");
    }
    let _ = write!(line, "{cmd}");
    let dir = sh.current_dir();
    if let Ok(sub) = dir.strip_prefix(root())
        && !sub.as_os_str().is_empty()
    {
        line = format!("(cd {} && {line})", sub.display());
    }
    // On stderr: stdout is for results (`cargo xtask console` prints only
    // the head's replies there).
    eprintln!("$ {line}");
    cmd.envs(env.iter().copied())
        .quiet()
        .run()
        .map_err(|error| anyhow!("{error}"))
}

/// `command` as a user would type it.
pub fn shown(command: &std::process::Command) -> String {
    let words = std::iter::once(command.get_program()).chain(command.get_args());
    words
        .map(|w| w.to_string_lossy())
        .collect::<Vec<_>>()
        .join(" ")
}

/// What a child left behind ([`finish`]).
pub struct Finished<O, E, R> {
    pub exit: crate::log::Exit,
    pub stdout: O,
    pub stderr: E,
    pub meanwhile: R,
}

/// Runs `child` (spawned with its stdout and stderr piped) to its end:
/// `stdout` and `stderr` each read their pipe on a thread of their own (so
/// that neither fills up and stalls it), `meanwhile` runs on this thread;
/// once it returns, `child` has `timeout` to exit before it is killed.
pub fn finish<O: Send, E: Send, R>(
    mut child: Child,
    name: &str,
    timeout: Duration,
    stdout: impl FnOnce(ChildStdout) -> O + Send,
    stderr: impl FnOnce(ChildStderr) -> E + Send,
    meanwhile: impl FnOnce() -> R,
) -> Result<Finished<O, E, R>> {
    let (Some(out), Some(err)) = (child.stdout.take(), child.stderr.take()) else {
        let _ = child.kill();
        let _ = child.wait();
        return Err(anyhow!(
            "{name} was started without piped stdout and stderr"
        ));
    };
    thread::scope(|scope| {
        let out = scope.spawn(move || stdout(out));
        let err = scope.spawn(move || stderr(err));
        let meanwhile = meanwhile();
        let waited = child.wait_timeout(timeout);
        let exit = if let Some(status) = waited.with_context(|| format!("waiting for {name}"))? {
            crate::log::Exit::Status(status)
        } else {
            let _ = child.kill();
            let _ = child.wait();
            crate::log::Exit::TimedOut(timeout)
        };
        let panicked = |what| anyhow!("the reader of {name}'s {what} panicked");
        Ok(Finished {
            exit,
            stdout: out.join().map_err(|_| panicked("stdout"))?,
            stderr: err.join().map_err(|_| panicked("stderr"))?,
            meanwhile,
        })
    })
}

/// A package of the repository that builds firmware images, each with its
/// own memory map (`memory.x`), in the one workspace and target directory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Package {
    /// The root package `idle-head`: the Pico image.
    Root,
    /// `boards/qemu/`, the package `idle-head-qemu`: the QEMU `lm3s6965evb` images.
    Qemu,
}

impl Package {
    /// Cargo arguments that select the package from the repository root
    /// (where cargo is run, so the root `.cargo/config.toml` applies).
    pub fn manifest_args(self) -> &'static [&'static str] {
        match self {
            Self::Root => &[],
            Self::Qemu => &["--package", "idle-head-qemu"],
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

/// The QEMU `lm3s6965evb` smoke image (`boards/qemu/src/main.rs`).
pub const QEMU: Image = Image::qemu("qemu");

impl Image {
    /// Bin `bin` of the QEMU package.
    pub const fn qemu(bin: &'static str) -> Self {
        Self {
            package: Package::Qemu,
            bin,
        }
    }

    /// Release ELF of this image in the target directory.
    pub fn elf(&self, metadata: &Metadata) -> PathBuf {
        metadata
            .target_dir
            .join(TARGET)
            .join("release")
            .join(self.bin)
    }

    /// `cargo build --release` for this image, run in the repository root,
    /// with the project's defmt level. The Pico image is the root package's
    /// only bin, so its command is the one users type.
    pub fn build(&self, root: &Path) -> Result<()> {
        let sh = Shell::new()?;
        sh.change_dir(root);
        let manifest = self.package.manifest_args();
        let bin = match self.package {
            Package::Root => None,
            Package::Qemu => Some(["--bin", self.bin]),
        };
        let bin = bin.iter().flatten();
        run(
            &sh,
            FIRMWARE_ENV,
            cmd!(sh, "cargo build --release {manifest...} {bin...}"),
        )
    }
}

/// The parts of `cargo metadata` this crate uses.
#[derive(Debug)]
pub struct Metadata {
    /// Where cargo puts build output (`target/` unless configured otherwise).
    pub target_dir: PathBuf,
}

/// Reads `cargo metadata` for the workspace (no dependency resolution).
pub fn metadata(root: &Path) -> Result<Metadata> {
    let main = MetadataCommand::new()
        .current_dir(root)
        .manifest_path(root.join("crates/Cargo.toml"))
        .no_deps()
        .exec()
        .context("running `cargo metadata`")?;
    Ok(Metadata {
        target_dir: main.target_directory.into(),
    })
}

#[cfg(test)]
mod tests {
    use std::io::Read;
    use std::process::{Command, Stdio};

    use super::*;
    use crate::log::Exit;

    fn spawn(script: &str) -> Child {
        let mut command = Command::new("sh");
        command.args(["-c", script]).stdin(Stdio::null());
        command.stdout(Stdio::piped()).stderr(Stdio::piped());
        command.spawn().unwrap()
    }

    fn length(mut pipe: impl Read) -> usize {
        let mut bytes = Vec::new();
        pipe.read_to_end(&mut bytes).unwrap();
        bytes.len()
    }

    #[test]
    fn both_pipes_are_read_and_a_hung_child_is_killed_at_the_timeout() {
        // More than a pipe holds on each stream: neither may stall the child.
        let script = "head -c 200000 /dev/zero; head -c 100000 /dev/zero >&2; exit 3";
        let long = Duration::from_secs(60);
        let done = finish(spawn(script), "sh", long, length, length, || 7).unwrap();
        assert_eq!(
            (done.stdout, done.stderr, done.meanwhile),
            (200_000, 100_000, 7)
        );
        assert!(matches!(done.exit, Exit::Status(status) if status.code() == Some(3)));
        let short = Duration::from_millis(200);
        let done = finish(
            spawn("exec sleep 30"),
            "sleep",
            short,
            length,
            length,
            || (),
        )
        .unwrap();
        assert!(matches!(done.exit, Exit::TimedOut(_)));
    }
}
