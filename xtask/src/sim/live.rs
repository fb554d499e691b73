//! A live run of the shipped Pico image in the emulator, for a person
//! (`cargo xtask panel --sim`) and the browser tests: real time, the USB
//! serial port bridged to the host (`live` in `sim/harness.mjs`).

use std::{
    io::{BufRead, BufReader, Write},
    path::Path,
    process::{Child, ChildStdout, Stdio},
    time::Duration,
};

use anyhow::Result;

use super::{event::Event, image, node, store::WORST};

/// The harness's argument for a live run of `elf`: flash functions for
/// `save` and `load`, the trigger inputs driven by `pin <n> 0|1` lines.
pub fn config(root: &Path, elf: &Path) -> Result<serde_json::Value> {
    let (_, config) = image::config(elf, "live.uf2")?;
    node::ensure(root)?;
    Ok(node::Config {
        wall: Duration::from_secs(24 * 3600),
        rom: Some(WORST),
        inputs: crate::board::PICO_INPUTS.to_vec(),
        live: true,
        ..config
    }
    .json())
}

/// Starts `elf` live: stdin takes bytes for the USB serial port
/// ([`send`]), stdout has the events ([`events`]).
pub fn start(root: &Path, elf: &Path) -> Result<Child> {
    let config = config(root, elf)?.to_string();
    node::harness(root, &config, Stdio::piped(), Stdio::inherit())
}

/// Sends `bytes` to the head's USB serial port: one line of hex digits.
pub fn send(stdin: &mut impl Write, bytes: &[u8]) -> std::io::Result<()> {
    stdin.write_all(format!("{}\n", hex::encode(bytes)).as_bytes())?;
    stdin.flush()
}

/// Hands the head's USB bytes to `each` until the end; why it ended.
pub fn events(stdout: ChildStdout, mut each: impl FnMut(Vec<u8>)) -> String {
    let mut why = "the emulator stopped".to_owned();
    for line in BufReader::new(stdout).lines().map_while(Result::ok) {
        match Event::parse(&line) {
            Ok(Event::Usb { hex, .. }) => each(hex.0),
            Ok(Event::End(end)) => why = format!("the emulator stopped ({:?})", end.why),
            Ok(_) => {}
            Err(e) => why = format!("{e:#}"),
        }
    }
    why
}
