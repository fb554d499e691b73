//! A live run of the shipped Pico image in the emulator, for a person
//! (`cargo xtask panel --sim`) and the browser tests: real time, the USB
//! serial port bridged to the host (`live` in `sim/harness.mjs`).

use std::{
    io::{BufRead, BufReader, Write},
    path::Path,
    process::{Child, ChildStdin, ChildStdout, Command, Stdio},
    time::Duration,
};

use anyhow::{Context, Result};

use super::event::Event;
use super::{harness, node, store::WORST};

/// A live emulator run: the harness, its stdin (bytes for the USB serial
/// port) and stdout (its events).
pub struct Live {
    pub child: Child,
    /// Bytes for the head's USB serial port, one line of hex digits each.
    pub stdin: ChildStdin,
    /// The harness's events, one JSON line each.
    pub stdout: ChildStdout,
}

/// What a live run reports.
#[derive(Debug)]
pub enum LiveEvent {
    /// Bytes the head sent on its USB serial port.
    Bytes(Vec<u8>),
    /// The CDC-ACM host configured the device: the port is open.
    Connected,
    /// The run ended, and why.
    End(String),
}

/// The harness's argument for a live run of `elf`: the settings store's
/// flash functions as in the store run (`save` and `load` work), the servo
/// slices' compare writes reported (`cc` events of slices 0, 1, 2: pitch,
/// roll, yaw), the trigger inputs GP2..GP5 driven by `pin <n> 0|1` lines.
pub fn config(root: &Path, elf: &Path) -> Result<serde_json::Value> {
    let (_, config) = harness::config(elf, "live.uf2")?;
    node::ensure(root)?;
    let config = node::Config {
        wall: Duration::from_secs(24 * 3600),
        rom: Some(WORST),
        // At their pulls until driven, as on a board: a button's input
        // reads released.
        inputs: harness::input_pins(),
        live: true,
        ..config
    };
    Ok(config.json())
}

/// Starts `elf` live in the emulator ([`config`]).
pub fn start(root: &Path, elf: &Path) -> Result<Live> {
    let config = config(root, elf)?;
    let mut child = Command::new("node")
        .arg("harness.mjs")
        .arg(config.to_string())
        .current_dir(node::folder(root))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .context("could not start `node` (is Node.js installed?)")?;
    let stdin = child.stdin.take().context("the harness's stdin")?;
    let stdout = child.stdout.take().context("the harness's stdout")?;
    Ok(Live {
        child,
        stdin,
        stdout,
    })
}

/// Sends `bytes` to the head's USB serial port.
pub fn send(stdin: &mut impl Write, bytes: &[u8]) -> std::io::Result<()> {
    let mut line = node::hex(bytes);
    line.push('\n');
    stdin.write_all(line.as_bytes())?;
    stdin.flush()
}

/// Reads the harness's events until it ends, handing each that matters
/// to `each`; the last is [`LiveEvent::End`].
pub fn events(stdout: ChildStdout, mut each: impl FnMut(LiveEvent)) {
    let mut why = "the emulator stopped".to_owned();
    for line in BufReader::new(stdout).lines().map_while(Result::ok) {
        match Event::parse(&line) {
            Ok(Event::Usb { hex, .. }) => each(LiveEvent::Bytes(hex)),
            Ok(Event::UsbConnected { .. }) => each(LiveEvent::Connected),
            Ok(Event::End { why: end, .. }) => why = format!("the emulator stopped ({end:?})"),
            Ok(_) => {}
            Err(e) => why = format!("{e:#}"),
        }
    }
    each(LiveEvent::End(why));
}
