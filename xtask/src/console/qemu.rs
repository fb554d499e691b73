//! A console session with the firmware in QEMU: UART0 on one socket for the
//! conversation, UART1 on another for the hang-up.

use std::{
    io::{Read, Write},
    os::unix::net::UnixStream,
    path::{Path, PathBuf},
    process::{Child, Command, Stdio},
    thread,
    time::{Duration, Instant},
};

use anyhow::{Context, Result};

use super::talk::{self, Talk};
use crate::log::Run;
use crate::qemu::{self, Echo};

/// Which run the image plays, and how QEMU's clock runs while it sleeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pace {
    /// A clean head for a person (semihosting argument `interactive`: no
    /// script or faults, until the hang-up) at the wall clock's pace.
    RealTime,
    /// The smoke run held for its console (`console`), idle time skipped.
    Fast,
}

/// A QEMU run with its console: the firmware's log and exit, and the
/// conversation (lines sent, replies, what ended it early).
pub struct QemuSession {
    pub run: Run,
    pub talk: Talk,
}

/// How long QEMU has to stop after the hang-up (the firmware fades out,
/// then prints its summary), and the reply reader to read a byte.
const AFTER_HANG_UP: Duration = Duration::from_secs(120);

/// Runs `elf` in QEMU held for its console: [`talk::converse`] on UART0,
/// then the hang-up (a byte on UART1): the firmware fades out, prints its
/// summary and exits, which closes the socket and ends the reader.
pub fn qemu_session(
    elf: &Path,
    input: impl Read,
    on_reply: &mut (impl FnMut(&[u8]) + Send),
    pace: Pace,
    echo: Echo,
    wait: Duration,
) -> Result<QemuSession> {
    let (child, [mut console, mut hang_up]) = spawn_connected(elf, pace, "console", Stdio::piped)?;
    let (run, talk) = qemu::finish(child, elf, AFTER_HANG_UP, echo, || {
        let (reader, timeout) = (console.try_clone()?, console.try_clone()?);
        let end = || -> Result<()> {
            hang_up.write_all(b"\0")?;
            // A firmware that does not stop must not hold the reader for ever.
            timeout.set_read_timeout(Some(AFTER_HANG_UP))?;
            Ok(())
        };
        let talk = talk::converse(input, &mut console, reader, on_reply, wait, end);
        Ok::<_, anyhow::Error>(talk)
    })?;
    Ok(QemuSession { run, talk: talk? })
}

/// Starts QEMU running `elf` for a console, its stdout and stderr `output`,
/// UART0 and UART1 on sockets it serves in a temporary folder of its own
/// (removed once both are connected; QEMU is stopped if they cannot be):
/// QEMU and the two connections.
pub fn spawn_connected(
    elf: &Path,
    pace: Pace,
    tag: &str,
    output: fn() -> Stdio,
) -> Result<(Child, [UnixStream; 2])> {
    let dir = std::env::temp_dir().join(format!("idle-head-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let [uart0, uart1] = ["uart0", "uart1"].map(|n| dir.join(format!("{n}.sock")));
    for path in [&uart0, &uart1] {
        let _ = std::fs::remove_file(path);
    }
    let serial = |path: &PathBuf| format!("unix:{},server=on,wait=on", path.display());
    let mut command = qemu_command(elf, pace, [&serial(&uart0), &serial(&uart1)]);
    let mut child = qemu::spawn(&mut command, output)?;
    // QEMU waits for each connection in turn before the image starts.
    let connected = connect(&uart0).and_then(|uart0| Ok([uart0, connect(&uart1)?]));
    let _ = std::fs::remove_dir_all(&dir);
    if connected.is_err() {
        let _ = child.kill();
        let _ = child.wait();
    }
    Ok((child, connected?))
}

/// QEMU running `elf` for a console: the run `pace` asks for, UART0 and
/// UART1 (the hang-up line) on the character devices `serials` (a socket,
/// `pty`, `null`).
pub fn qemu_command(elf: &Path, pace: Pace, [uart0, uart1]: [&str; 2]) -> Command {
    let (sleep, run) = match pace {
        Pace::RealTime => (true, "interactive"),
        Pace::Fast => (false, "console"),
    };
    let semihosting = format!("enable=on,target=native,arg=idle-head,arg={run}");
    let mut command = qemu::qemu_command(elf, sleep, &["-display", "none", "-monitor", "none"]);
    command.args(["-semihosting-config", &semihosting]);
    command.args(["-serial", uart0, "-serial", uart1]);
    command
}

/// Connects to a socket QEMU serves, waiting for it to appear.
pub fn connect(path: &Path) -> Result<UnixStream> {
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        match UnixStream::connect(path) {
            Ok(stream) => return Ok(stream),
            Err(e) if Instant::now() > deadline => {
                return Err(e).with_context(|| format!("connecting to {}", path.display()));
            }
            Err(_) => thread::sleep(Duration::from_millis(20)),
        }
    }
}
