//! Where things are in the repository, the process runners ([`run`],
//! [`finish`] with a time limit), and the firmware images.

use std::{
    io::Write,
    path::{Path, PathBuf},
    process::{Child, ChildStderr, ChildStdout, Command, ExitStatus, Stdio},
    sync::{
        OnceLock,
        atomic::{AtomicU32, Ordering},
    },
    thread,
    time::Duration,
};

use anyhow::{Context, Result, anyhow, bail, ensure};
use cargo_metadata::MetadataCommand;
use wait_timeout::ChildExt;
use xshell::{Cmd, Shell, cmd};

/// The firmware's compilation target (ARMv6-M: RP2040's Cortex-M0+, QEMU's Cortex-M0).
pub const TARGET: &str = "thumbv6m-none-eabi";

/// Variables set for a command, whatever the caller's environment says.
pub type Env = &'static [(&'static str, &'static str)];

/// The environment of every firmware build: the expected QEMU log's defmt
/// level.
pub const FIRMWARE_ENV: Env = &[("DEFMT_LOG", "info")];

/// A host build linted as it compiles, as `cargo clippy -- -D warnings`
/// lints: clippy's driver (rustup's proxy) compiles the workspace's packages,
/// so the dependencies are compiled once, not again by a check. Not for the
/// firmware images: the driver turns MIR optimisations off.
pub const LINTED: Env = &[
    ("RUSTC_WORKSPACE_WRAPPER", "clippy-driver"),
    ("CLIPPY_ARGS", "-Dwarnings"),
];

/// The repository root (commands run from any folder of it).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask/ lives in the repository")
        .into()
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

/// Echoes `cmd` on stderr as typed from the repository root (`(cd dir &&
/// VAR=value program args)`), then runs it with `env` and inherited output;
/// fails unless it exits with 0.
pub fn run(sh: &Shell, env: &[(&str, &str)], cmd: Cmd<'_>) -> Result<()> {
    let vars: String = env.iter().flat_map(|&(k, v)| [k, "=", v, " "]).collect();
    let line = match sh.current_dir().strip_prefix(root()) {
        Ok(sub) if !sub.as_os_str().is_empty() => format!("(cd {} && {vars}{cmd})", sub.display()),
        _ => format!("{vars}{cmd}"),
    };
    eprintln!("$ {line}");
    (cmd.envs(env.iter().copied()).quiet().run()).map_err(|error| anyhow!("{error}"))
}

/// How a child process ended ([`finish`]).
#[derive(Debug, Clone, Copy)]
pub enum Exit {
    /// QEMU exited (semihosting exit code, 0 = success).
    Status(ExitStatus),
    TimedOut(Duration),
}

/// What a child left behind ([`finish`]).
pub struct Finished<O, E, R> {
    pub exit: Exit,
    pub stdout: O,
    pub stderr: E,
    pub meanwhile: R,
}

/// Runs `child` (its stdout and stderr piped) to its end: `stdout` and
/// `stderr` read their pipes on threads of their own (neither may fill up
/// and stall it) while `meanwhile` runs; then `child` has `timeout` to exit
/// before it is killed.
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
        bail!("{name} was started without piped stdout and stderr");
    };
    thread::scope(|scope| {
        let out = scope.spawn(move || stdout(out));
        let err = scope.spawn(move || stderr(err));
        let meanwhile = meanwhile();
        let waited = child.wait_timeout(timeout);
        let exit = if let Some(status) = waited.with_context(|| format!("waiting for {name}"))? {
            Exit::Status(status)
        } else {
            let _ = child.kill();
            let _ = child.wait();
            Exit::TimedOut(timeout)
        };
        let panicked = |what| anyhow!("the reader of {name}'s {what} panicked");
        let stdout = out.join().map_err(|_| panicked("stdout"))?;
        let stderr = err.join().map_err(|_| panicked("stderr"))?;
        Ok(Finished {
            exit,
            stdout,
            stderr,
            meanwhile,
        })
    })
}

/// Runs `command` with `input` on its stdin and its stderr passed on; its
/// stdout, printed as well, and how it ended.
pub fn output(command: &mut Command, input: &[u8]) -> Result<(String, ExitStatus)> {
    let program = command.get_program().to_string_lossy().into_owned();
    let io = command.stdin(Stdio::piped()).stdout(Stdio::piped());
    let mut child = io
        .spawn()
        .with_context(|| format!("could not start {program}"))?;
    child.stdin.take().context("its stdin")?.write_all(input)?;
    let out = child.wait_with_output()?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    print!("{text}");
    Ok((text, out.status))
}

/// Writes `contents` to `path`, creating its folder, through a file renamed
/// over it (no reader of the runs side by side sees half a file).
pub fn write(path: &Path, contents: impl AsRef<[u8]>) -> Result<()> {
    static CALLS: AtomicU32 = AtomicU32::new(0);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let n = CALLS.fetch_add(1, Ordering::Relaxed);
    let mut partial = path.as_os_str().to_owned();
    partial.push(format!(".{}-{n}.partial", std::process::id()));
    let written = std::fs::write(&partial, contents).and_then(|()| std::fs::rename(&partial, path));
    written.with_context(|| format!("writing {}", path.display()))
}

/// Fails with every one of `problems`, if there are any.
pub fn verdict(problems: &[String]) -> Result<()> {
    ensure!(problems.is_empty(), "{}", problems.join("; "));
    Ok(())
}

/// Whether a command's `what` passed; if not, `<what> FAILED: <error>`.
pub fn passed(what: &str, result: &Result<()>) -> bool {
    if let Err(error) = result {
        println!("{what} FAILED: {error:#}");
    }
    result.is_ok()
}

/// The program a stage apart or a console runs: this one, or the copy of it
/// [`keep_exe`] made.
static EXE: OnceLock<PathBuf> = OnceLock::new();

pub fn exe() -> Result<PathBuf> {
    Ok(EXE.get().cloned().unwrap_or(std::env::current_exe()?))
}

/// Copies this program into `dir`, for [`exe`]: `cargo xtask test` builds the
/// xtask again where it lies (its lint stage) while its stages start it.
pub fn keep_exe(dir: &Path) -> Result<()> {
    let exe = std::env::current_exe()?;
    let copy = dir.join(exe.file_name().context("the xtask's file name")?);
    let partial = copy.with_extension("partial");
    std::fs::create_dir_all(dir)?;
    let copied = std::fs::copy(&exe, &partial).and_then(|_| std::fs::rename(&partial, &copy));
    copied.with_context(|| format!("copying the xtask to {}", copy.display()))?;
    let _ = EXE.set(copy);
    Ok(())
}

/// Set by `cargo xtask test` on the emulator stages it runs side by side on
/// images built already: [`Image::build`] then builds nothing.
pub const PREBUILT: &str = "IDLE_HEAD_PREBUILT";

pub fn prebuilt() -> bool {
    std::env::var_os(PREBUILT).is_some()
}

/// How many runs share the cores ([`PREBUILT`]'s value, else 1), by which
/// an emulator run's wall-time limit grows.
pub fn side_by_side() -> u32 {
    let value = std::env::var(PREBUILT).ok().and_then(|v| v.parse().ok());
    value.unwrap_or(1).max(1)
}

/// A firmware image: a `[[bin]]` of a package, built with `cargo build
/// --release` in its folder.
#[derive(Debug, Clone, Copy)]
pub struct Image {
    /// Bin target name, also the ELF file name.
    pub bin: &'static str,
    /// The package's folder (its `.cargo/config.toml` picks the target).
    pub dir: &'static str,
    pub target: &'static str,
    /// The package to select (`--package … --bin …`), if not the folder's.
    pub package: Option<&'static str>,
}

/// The Raspberry Pi Pico image: plain `cargo build --release`.
pub const PICO: Image = Image {
    bin: "pico",
    dir: ".",
    target: TARGET,
    package: None,
};

/// The QEMU `lm3s6965evb` smoke image (`boards/qemu/src/main.rs`).
pub const QEMU: Image = Image::qemu("qemu");

impl Image {
    /// Bin `bin` of the QEMU package (`boards/qemu/`), built from the root.
    pub const fn qemu(bin: &'static str) -> Self {
        Self {
            bin,
            dir: ".",
            target: TARGET,
            package: Some("idle-head-qemu"),
        }
    }

    /// Release ELF of this image in the target directory.
    pub fn elf(&self, metadata: &Metadata) -> PathBuf {
        metadata
            .target_dir
            .join(self.target)
            .join("release")
            .join(self.bin)
    }

    /// `cargo build --release` for this image, with [`FIRMWARE_ENV`].
    pub fn build(&self, root: &Path) -> Result<()> {
        if prebuilt() {
            return Ok(());
        }
        let sh = Shell::new()?;
        sh.change_dir(root.join(self.dir));
        let select = self.package.map(|p| ["--package", p, "--bin", self.bin]);
        let select = select.iter().flatten();
        let build = cmd!(sh, "cargo build --release {select...}");
        run(&sh, FIRMWARE_ENV, build)
    }
}

/// The parts of `cargo metadata` this crate uses.
#[derive(Debug)]
pub struct Metadata {
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

    use super::*;

    #[test]
    fn both_pipes_are_read_and_a_hung_child_is_killed_at_the_timeout() {
        let run = |script: &str, timeout| {
            let mut command = Command::new("sh");
            command.args(["-c", script]).stdin(Stdio::null());
            let child = command.stdout(Stdio::piped()).stderr(Stdio::piped());
            let length = |mut pipe: Box<dyn Read>| pipe.read_to_end(&mut Vec::new()).unwrap();
            let (out, err) = (|p| length(Box::new(p)), |p| length(Box::new(p)));
            finish(child.spawn().unwrap(), "sh", timeout, out, err, || 7).unwrap()
        };
        // More than a pipe holds on each stream: neither may stall the child.
        let script = "head -c 200000 /dev/zero; head -c 100000 /dev/zero >&2; exit 3";
        let done = run(script, Duration::from_secs(60));
        assert_eq!(
            (done.stdout, done.stderr, done.meanwhile),
            (200_000, 100_000, 7)
        );
        assert!(matches!(done.exit, Exit::Status(status) if status.code() == Some(3)));
        let done = run("exec sleep 30", Duration::from_millis(200));
        assert!(matches!(done.exit, Exit::TimedOut(_)));
    }
}
