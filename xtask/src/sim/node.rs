//! Node, the emulator package and a run of `sim/harness.mjs` ([`Config`]).

use std::{
    io::{BufRead, BufReader, Write},
    path::{Path, PathBuf},
    process::{Child, Command, Stdio},
    time::Duration,
};

use anyhow::{Context, Result, bail, ensure};
use serde::{Serialize, Serializer};
use serde_json::Value;
use xshell::{Shell, cmd};

use super::event::Event;
use crate::{project, project::Exit, setup};

/// The folder with the harness and its `package.json`.
pub fn folder(root: &Path) -> PathBuf {
    root.join("sim")
}

/// Makes sure `node` and `npm` run and the pinned emulator is installed.
pub fn ensure(root: &Path) -> Result<()> {
    npm_ci(&folder(root), &["rp2040js"], &[])
}

/// Makes sure `node` and `npm` run (apt-get installs them when root) and
/// `packages` are in `dir` as `package-lock.json` pins them (else `npm ci`).
pub fn npm_ci(dir: &Path, packages: &[&str], env: &[(&str, &str)]) -> Result<()> {
    let what = "Node.js (20 or newer) and npm (packages `nodejs npm` on Debian and Ubuntu)";
    for program in ["node", "npm"] {
        setup::ensure_program(program, &["nodejs", "npm"], what)?;
    }
    let read = |path: PathBuf| -> Value {
        let bytes = std::fs::read(path).unwrap_or_default();
        serde_json::from_slice(&bytes).unwrap_or_default()
    };
    let lock = read(dir.join("package-lock.json"));
    if lock.is_null() {
        bail!("{}/package-lock.json is missing or not JSON", dir.display());
    }
    let stale = packages.iter().any(|name| {
        let pinned = &lock["packages"][format!("node_modules/{name}")]["version"];
        let installed = read(dir.join(format!("node_modules/{name}/package.json")));
        pinned.is_null() || installed["version"] != *pinned
    });
    if stale {
        let sh = Shell::new()?;
        sh.change_dir(dir);
        project::run(&sh, env, cmd!(sh, "npm ci --no-audit --no-fund"))
            .with_context(|| format!("installing with `npm ci` in {}", dir.display()))?;
    }
    Ok(())
}

/// The harness's run (default: nothing scripted, no ROM, no power cycle);
/// times go to it in ns, bytes as hex digits.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Config {
    pub flash: PathBuf,
    pub vtor: u64,
    pub rtt: u64,
    pub pins: Vec<u8>,
    /// PWM slices whose compare writes to report.
    pub slices: Vec<u8>,
    /// Function whose cycles to report per call (0: none); stack region
    /// to scan for paint.
    pub probe: u64,
    pub stack: Option<(u64, u64)>,
    #[serde(rename = "ns", serialize_with = "ns")]
    pub virtual_time: Duration,
    #[serde(rename = "wall_ms", serialize_with = "ms")]
    pub wall: Duration,
    /// No log byte or pin edge for this long ends the run.
    #[serde(rename = "silence_ns", serialize_with = "ns")]
    pub silence: Duration,
    /// Bytes for UART0's RX line, per boot.
    pub uart: Vec<UartScript>,
    /// Chunks for the USB serial port, each at its time (boot 0).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub usb: Vec<Chunk>,
    /// DMX512 on UART1 RX (`sim/dmx.mjs`); a boot ROM with the flash
    /// functions (`sim/rom.mjs`); bytes over the flash before power-on;
    /// when the power goes off and on again.
    pub dmx: Option<Value>,
    pub rom: Option<FlashTiming>,
    pub flash_fill: Option<Fill>,
    #[serde(rename = "power_cycles_ns", serialize_with = "ns_each")]
    pub power_cycles: Vec<Duration>,
    /// A live run (`live.rs`): real time, stdin to the USB serial port.
    pub live: bool,
    /// GPIOs driven from outside (at their pull until driven).
    pub inputs: Vec<u8>,
    pub script: Option<PinScript>,
    pub stream: Option<LineStream>,
    /// An HLK-LD2450 radar on GP13 (`sim/radar.mjs`).
    pub radar: Option<Value>,
    /// The flash's unique id, 16 hex digits (none: it answers all ones).
    pub uid: Option<String>,
}

/// Bytes sent at a time.
#[derive(Debug, Clone, Serialize)]
pub struct Chunk {
    #[serde(rename = "hex", serialize_with = "hex::serialize")]
    pub bytes: Vec<u8>,
    #[serde(rename = "at_ns", serialize_with = "ns")]
    pub at: Duration,
}

impl Chunk {
    pub fn new(bytes: impl Into<Vec<u8>>, at: Duration) -> Self {
        let bytes = bytes.into();
        Self { bytes, at }
    }
}

/// Bytes for the flash, at an address.
#[derive(Debug, Clone, Serialize)]
pub struct Fill {
    pub addr: u64,
    #[serde(serialize_with = "hex::serialize")]
    pub hex: Vec<u8>,
}

/// `count` console lines on `"uart"` or `"usb"`, one every `every` from
/// `start` on, cycling through `lines` (`sim/stream.mjs`).
#[derive(Debug, Clone, Serialize)]
pub struct LineStream {
    pub port: &'static str,
    #[serde(rename = "start_ns", serialize_with = "ns")]
    pub start: Duration,
    #[serde(rename = "every_ns", serialize_with = "ns")]
    pub every: Duration,
    pub count: usize,
    pub lines: Vec<StreamLine>,
}

/// One line of a [`LineStream`]'s cycle: as it is, or a command in machine
/// mode (`#<n> … *<crc>` with n the line's index mod 100000).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StreamLine {
    #[serde(rename = "text")]
    Plain(&'static str),
    Machine(&'static str),
}

/// Boot 0's pin levels and UART0 lines (each `early`), times from the
/// first frame (when `anchor_slice` is enabled).
#[derive(Debug, Clone, Default, Serialize)]
pub struct PinScript {
    pub anchor_slice: u8,
    pub pins: Vec<PinLevel>,
    pub lines: Vec<Chunk>,
    #[serde(rename = "early_ns", serialize_with = "ns")]
    pub early: Duration,
}

/// A pin driven high or low at a time.
#[derive(Debug, Clone, Serialize)]
pub struct PinLevel {
    #[serde(rename = "at_ns", serialize_with = "ns")]
    pub at: Duration,
    pub pin: u8,
    pub high: bool,
}

/// How long the flash is busy: one 4 KiB sector erase, one page program.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct FlashTiming {
    #[serde(rename = "erase_ns", serialize_with = "ns")]
    pub erase: Duration,
    #[serde(rename = "program_ns", serialize_with = "ns")]
    pub program: Duration,
}

/// Bytes on UART0's RX line in boot `boot` from their time on, one every
/// `byte_time`; those at the indices in `errors` with a framing error.
#[derive(Debug, Clone, Serialize)]
pub struct UartScript {
    pub boot: usize,
    #[serde(flatten)]
    pub bytes: Chunk,
    #[serde(rename = "byte_ns", serialize_with = "ns")]
    pub byte_time: Duration,
    pub errors: Vec<usize>,
}

impl UartScript {
    /// At 115200 baud, undamaged.
    pub fn new(boot: usize, bytes: impl Into<Vec<u8>>, start: Duration) -> Self {
        Self {
            boot,
            bytes: Chunk::new(bytes, start),
            byte_time: BYTE_TIME,
            errors: Vec::new(),
        }
    }
}

/// cortex-m-rt's `paint-stack` fill: the harness reads the stack's depth
/// from what is left of it.
pub const STACK_PAINT: u32 = 0xcccc_cccc;

/// One byte at 115200 baud, 8N1: 10 bits.
pub const BYTE_TIME: Duration = Duration::from_nanos(1_000_000_000 * 10 / 115_200);

impl Config {
    /// The harness's configuration, as JSON.
    pub fn json(&self) -> Value {
        let mut json = serde_json::to_value(self).unwrap_or_default();
        json["paint"] = STACK_PAINT.into();
        for key in ["script", "stream"] {
            if json[key].is_object() {
                json[key]["byte_ns"] = nanos(BYTE_TIME).into();
            }
        }
        json
    }
}

pub fn nanos(duration: Duration) -> u64 {
    u64::try_from(duration.as_nanos()).unwrap_or(u64::MAX)
}

fn ns<S: Serializer>(duration: &Duration, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_u64(nanos(*duration))
}

fn ms<S: Serializer>(duration: &Duration, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_u128(duration.as_millis())
}

fn ns_each<S: Serializer>(durations: &[Duration], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(durations.iter().map(|d| nanos(*d)))
}

/// Wall time the harness has beyond its own limit: node's start-up.
const GRACE: Duration = Duration::from_secs(15);

/// Runs the harness; its events, in order. Fails if node does not start,
/// fails, prints a line that is no known event, or outlives the wall time.
pub fn run(root: &Path, config: &Config) -> Result<Vec<Event>> {
    // The configuration goes in a file: a run of a thousand scripted
    // chunks is more than a command line may carry.
    let mut config = config.clone();
    config.wall *= project::side_by_side();
    let mut file = tempfile::Builder::new().suffix(".json").tempfile()?;
    file.write_all(config.json().to_string().as_bytes())?;
    let arg = format!("@{}", file.path().display());
    let child = harness(root, &arg, Stdio::null(), Stdio::piped());
    // Read to the end (past a bad line too: node never waits on a full
    // pipe); the first bad line is the error.
    let events = |stdout| -> Result<Vec<Event>> {
        let lines = BufReader::new(stdout).lines().map_while(Result::ok);
        let events: Vec<Result<Event>> = lines.map(|line| Event::parse(&line)).collect();
        events.into_iter().collect()
    };
    let all = |stderr| std::io::read_to_string(stderr).unwrap_or_default();
    let limit = config.wall + GRACE;
    let done = child.and_then(|child| project::finish(child, "node", limit, events, all, || ()))?;
    let Exit::Status(status) = done.exit else {
        bail!(
            "the emulator made no progress: node was killed after {} s of wall time",
            limit.as_secs()
        );
    };
    let events = done.stdout?;
    ensure!(
        status.success() || matches!(events.last(), Some(Event::End(_))),
        "the emulator harness failed ({status}):\n{}",
        done.stderr.trim_end()
    );
    Ok(events)
}

/// Starts the harness on `arg` (its config, or `@file`), stdout piped.
pub fn harness(root: &Path, arg: &str, stdin: Stdio, stderr: Stdio) -> Result<Child> {
    let mut node = Command::new("node");
    node.args(["harness.mjs", arg]).current_dir(folder(root));
    node.stdin(stdin)
        .stdout(Stdio::piped())
        .stderr(stderr)
        .spawn()
        .context("could not start `node` (is Node.js installed?)")
}
