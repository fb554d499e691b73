//! A console session with the firmware in QEMU: UART0 on one loopback
//! connection for the conversation, UART1 on another for the hang-up.

use std::{
    io::{ErrorKind, Read, Write},
    net::{Ipv4Addr, TcpListener, TcpStream},
    path::Path,
    process::{Child, Command, Stdio},
    thread,
    time::{Duration, Instant},
};

use anyhow::{Result, bail, ensure};

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

/// How long QEMU has to stop after the hang-up (the firmware fades out,
/// then prints its summary), and the reply reader to read a byte.
const AFTER_HANG_UP: Duration = Duration::from_secs(120);

/// Runs `elf` in QEMU held for its console: [`talk::converse`] on UART0,
/// then the hang-up (a byte on UART1): the firmware fades out, prints its
/// summary and exits, which closes the socket and ends the reader. The run
/// (the firmware's log and exit) and the conversation (lines sent, replies,
/// what ended it early).
pub fn qemu_session(
    elf: &Path,
    input: impl Read,
    on_reply: &mut (impl FnMut(&[u8]) + Send),
    pace: Pace,
    echo: Echo,
    wait: Duration,
) -> Result<(Run, Talk)> {
    let (child, [mut console, mut hang_up]) = spawn_connected(elf, pace, Stdio::piped)?;
    let (run, talk) = qemu::finish(child, elf, AFTER_HANG_UP, echo, || {
        let reader = console.try_clone()?;
        // A firmware that does not stop must not hold the reader for ever
        // after the hang-up (a read that times out before it reads on).
        reader.set_read_timeout(Some(AFTER_HANG_UP))?;
        let end = || Ok(hang_up.write_all(b"\0")?);
        let talk = talk::converse(input, &mut console, reader, on_reply, wait, end);
        Ok::<_, anyhow::Error>(talk)
    })?;
    Ok((run, talk?))
}

/// Starts QEMU running `elf` for a console, its stdout and stderr `output`,
/// UART0 and UART1 connected to loopback ports here (else it is stopped).
pub fn spawn_connected(
    elf: &Path,
    pace: Pace,
    output: fn() -> Stdio,
) -> Result<(Child, [TcpStream; 2])> {
    let [uart0, uart1] = [listen()?, listen()?];
    let serial = |listener: &TcpListener| -> Result<String> {
        Ok(format!("tcp:{},nodelay=on", listener.local_addr()?))
    };
    let mut command = qemu_command(elf, pace, [&serial(&uart0)?, &serial(&uart1)?]);
    let mut child = qemu::spawn(&mut command, output)?;
    let connected = accept(&uart0, &mut child).and_then(|u0| Ok([u0, accept(&uart1, &mut child)?]));
    if connected.is_err() {
        let _ = child.kill();
        let _ = child.wait();
    }
    Ok((child, connected?))
}

/// QEMU running `elf` for a console at `pace`, UART0 and UART1 (the hang-up
/// line) on the character devices given (a socket, `pty`, `null`).
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

/// A listener on a free loopback port, for QEMU to connect a character
/// device to (`tcp:ADDR`).
pub fn listen() -> Result<TcpListener> {
    Ok(TcpListener::bind((Ipv4Addr::LOCALHOST, 0))?)
}

/// The connection QEMU (`child`) makes to `listener` as it starts.
pub fn accept(listener: &TcpListener, child: &mut Child) -> Result<TcpStream> {
    let deadline = Instant::now() + Duration::from_secs(20);
    listener.set_nonblocking(true)?;
    loop {
        match listener.accept() {
            Ok((stream, _)) => {
                stream.set_nonblocking(false)?;
                stream.set_nodelay(true)?;
                return Ok(stream);
            }
            Err(e) if e.kind() != ErrorKind::WouldBlock => return Err(e.into()),
            Err(_) => {
                if let Some(status) = child.try_wait()? {
                    bail!("QEMU stopped ({status}) before it connected to {listener:?}");
                }
                ensure!(
                    Instant::now() < deadline,
                    "QEMU did not connect within 20 s"
                );
                thread::sleep(Duration::from_millis(20));
            }
        }
    }
}
