//! Node, the emulator package and one run of `sim/harness.mjs`.

use std::{
    fmt::Write as _,
    io::{BufRead, BufReader, Read},
    path::{Path, PathBuf},
    process::{Command, Stdio},
    time::Duration,
};

use anyhow::{Context, Result, bail};
use serde_json::{Value, json};

use super::event::Event;
use crate::{log::Exit, project, setup};
use xshell::cmd;

/// The folder with the harness and its `package.json`.
pub fn folder(root: &Path) -> PathBuf {
    root.join("sim")
}

/// Makes sure `node` and `npm` run (installing them with apt-get when root on
/// Debian or Ubuntu) and that the pinned emulator is installed (`npm ci`).
pub fn ensure(root: &Path) -> Result<()> {
    npm_ci(&folder(root), &["rp2040js"], &[])
}

/// Makes sure `node` and `npm` run and that `packages` are installed in
/// `dir`'s `node_modules` as its `package-lock.json` pins them: else
/// `npm ci` there (with `env`).
pub fn npm_ci(dir: &Path, packages: &[&str], env: &[(&str, &str)]) -> Result<()> {
    let what = "Node.js (20 or newer) and npm (packages `nodejs npm` on Debian and Ubuntu)";
    for program in ["node", "npm"] {
        setup::ensure_program(program, &["nodejs", "npm"], what)?;
    }
    let read = |path: PathBuf| -> Option<Value> {
        serde_json::from_slice(&std::fs::read(path).ok()?).ok()
    };
    let lock = read(dir.join("package-lock.json"))
        .with_context(|| format!("{}/package-lock.json is missing or not JSON", dir.display()))?;
    let stale = packages.iter().any(|name| {
        let pinned = &lock["packages"][format!("node_modules/{name}")]["version"];
        let installed = read(dir.join(format!("node_modules/{name}/package.json")))
            .map_or(Value::Null, |package| package["version"].clone());
        pinned.is_null() || installed != *pinned
    });
    if stale {
        let sh = project::shell(".")?;
        sh.change_dir(dir);
        project::run(&sh, env, cmd!(sh, "npm ci --no-audit --no-fund"))
            .with_context(|| format!("installing with `npm ci` in {}", dir.display()))?;
    }
    Ok(())
}

/// What the harness is asked to run (by default: nothing scripted, no
/// ROM, no power cycle).
#[derive(Debug, Clone, Default)]
pub struct Config {
    pub flash: PathBuf,
    pub vtor: u64,
    pub rtt: u64,
    pub pins: Vec<u8>,
    /// PWM slices whose compare writes to report.
    pub slices: Vec<u8>,
    /// Function whose cycles to report per call, or 0.
    pub probe: u64,
    /// Stack region to scan for paint, if painted.
    pub stack: Option<(u64, u64)>,
    pub virtual_time: Duration,
    pub wall: Duration,
    /// Virtual time without a log byte or a pin edge after which the run ends.
    pub silence: Duration,
    /// Bytes for UART0's RX line, per boot.
    pub uart: Vec<UartScript>,
    /// Bytes for the USB serial port (CDC-ACM), if any, and when to send
    /// them (boot 0).
    pub usb: Option<(Vec<u8>, Duration)>,
    /// A boot ROM with the flash functions (`sim/rom.mjs`), if any: how
    /// long a 4 KiB sector erase and a 256-byte page program keep the flash
    /// busy.
    pub rom: Option<FlashTiming>,
    /// Bytes written over the image's flash before power-on, and where.
    pub flash_fill: Option<(u64, Vec<u8>)>,
    /// Virtual times at which the power goes off and on again.
    pub power_cycles: Vec<Duration>,
    /// A live run: real time, stdin to the USB serial port, for as long
    /// as stdin is open (`live.rs`).
    pub live: bool,
    /// Chunks for the USB serial port, each sent at its time (instead of
    /// `usb`).
    pub usb_chunks: Vec<(Vec<u8>, Duration)>,
    /// DMX512 frames on UART1's RX line (`sim/dmx.mjs`).
    pub dmx: Option<Value>,
    /// GPIOs the outside drives as inputs (at their pull until driven).
    pub inputs: Vec<u8>,
    /// Boot 0's script of pin levels and console lines, if any.
    pub script: Option<PinScript>,
    /// A stream of console lines made as they go out (`sim/stream.mjs`).
    pub stream: Option<LineStream>,
    /// An HLK-LD2450 radar on GP13 (`sim/radar.mjs`; see `radar.rs`).
    pub radar: Option<Value>,
    /// The flash's unique id (none: the flash answers all ones).
    pub uid: Option<u64>,
}

/// A stream of console lines on UART0 or USB (`sim/stream.mjs`): `count`
/// lines, one every `every` from `start` on, cycling through `lines`.
#[derive(Debug, Clone)]
pub struct LineStream {
    /// The port: `"uart"` or `"usb"`.
    pub port: &'static str,
    /// When the first line goes out (boot 0).
    pub start: Duration,
    /// The time from one line to the next.
    pub every: Duration,
    /// How many lines.
    pub count: usize,
    /// The lines, in turn: plain, or a machine-mode command (`#<n> … *<crc>`
    /// with n the line's index mod 100000).
    pub lines: Vec<StreamLine>,
}

/// One line of a [`LineStream`]'s cycle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StreamLine {
    /// As it is.
    Plain(&'static str),
    /// This command in machine mode.
    Machine(&'static str),
}

/// Boot 0's script, its times counted from the first frame (when the
/// slice `anchor` is enabled).
#[derive(Debug, Clone, Default)]
pub struct PinScript {
    /// The PWM slice whose enable is the first frame.
    pub anchor: u8,
    /// Pin levels: when, which GPIO, high or low.
    pub pins: Vec<(Duration, u8, bool)>,
    /// Console lines (with their line end) for UART0: when each must be in.
    pub lines: Vec<(Duration, Vec<u8>)>,
    /// How much before its time a line's last byte goes in.
    pub early: Duration,
}

/// How long the flash is busy per operation.
#[derive(Debug, Clone, Copy)]
pub struct FlashTiming {
    /// One 4 KiB sector erase.
    pub erase: Duration,
    pub program: Duration,
}

/// Bytes the harness puts on UART0's RX line in one boot.
#[derive(Debug, Clone)]
pub struct UartScript {
    pub boot: usize,
    pub bytes: Vec<u8>,
    /// Virtual time of the first, since the boot's start.
    pub start: Duration,
    /// Time per byte (the line rate).
    pub byte_time: Duration,
    /// Indices of the bytes received with a framing error (line noise).
    pub errors: Vec<usize>,
}

impl UartScript {
    /// `bytes` in boot `boot` from `start` on, at 115200 baud, undamaged.
    pub fn new(boot: usize, bytes: Vec<u8>, start: Duration) -> Self {
        Self {
            boot,
            bytes,
            start,
            byte_time: super::exchange::BYTE_TIME,
            errors: Vec::new(),
        }
    }
}

impl Config {
    /// The harness's command-line argument.
    pub fn json(&self) -> Value {
        json!({
            "flash": self.flash,
            "vtor": self.vtor,
            "rtt": self.rtt,
            "pins": self.pins,
            "slices": self.slices,
            "probe": self.probe,
            "stack": self.stack.map(|(low, high)| [low, high]),
            "paint": super::image::STACK_PAINT,
            "ns": nanos(self.virtual_time),
            "wall_ms": self.wall.as_millis(),
            "silence_ns": nanos(self.silence),
            "uart": self.uart.iter().map(|uart| json!({
                "boot": uart.boot,
                "hex": hex(&uart.bytes),
                "at_ns": nanos(uart.start),
                "byte_ns": nanos(uart.byte_time),
                "errors": uart.errors,
            })).collect::<Vec<_>>(),
            "usb": if self.usb_chunks.is_empty() {
                self.usb.as_ref().map(|(bytes, at)| json!({
                    "hex": hex(bytes),
                    "at_ns": nanos(*at),
                }))
            } else {
                Some(Value::Array(self.usb_chunks.iter().map(|(bytes, at)| json!({
                    "hex": hex(bytes),
                    "at_ns": nanos(*at),
                })).collect()))
            },
            "dmx": self.dmx,
            "radar": self.radar,
            "uid": self.uid.map(|id| format!("{id:016x}")),
            "rom": self.rom.map(|rom| json!({
                "erase_ns": nanos(rom.erase),
                "program_ns": nanos(rom.program),
            })),
            "flash_fill": self.flash_fill.as_ref().map(|(addr, bytes)| json!({
                "addr": addr,
                "hex": hex(bytes),
            })),
            "power_cycles_ns": self.power_cycles.iter().map(|at| nanos(*at)).collect::<Vec<_>>(),
            "live": self.live,
            "inputs": self.inputs,
            "script": self.script.as_ref().map(|script| json!({
                "anchor_slice": script.anchor,
                "pins": script.pins.iter().map(|(at, pin, high)| json!({
                    "at_ns": nanos(*at),
                    "pin": pin,
                    "high": high,
                })).collect::<Vec<_>>(),
                "lines": script.lines.iter().map(|(at, bytes)| json!({
                    "at_ns": nanos(*at),
                    "hex": hex(bytes),
                })).collect::<Vec<_>>(),
                "byte_ns": nanos(super::exchange::BYTE_TIME),
                "early_ns": nanos(script.early),
            })),
            "stream": self.stream.as_ref().map(|stream| json!({
                "port": stream.port,
                "start_ns": nanos(stream.start),
                "every_ns": nanos(stream.every),
                "count": stream.count,
                "byte_ns": nanos(super::exchange::BYTE_TIME),
                "lines": stream.lines.iter().map(|line| match line {
                    StreamLine::Plain(text) => json!({ "text": text }),
                    StreamLine::Machine(command) => json!({ "machine": command }),
                }).collect::<Vec<_>>(),
            })),
        })
    }
}

/// `bytes` as lower-case hex digits, as the harness reads them.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().fold(String::new(), |mut text, byte| {
        let _ = write!(text, "{byte:02x}");
        text
    })
}

pub fn nanos(duration: Duration) -> u64 {
    u64::try_from(duration.as_nanos()).unwrap_or(u64::MAX)
}

/// Runs the harness; returns its events, in order. Fails if node cannot be
/// started, exits with an error, prints a line that is not a known event,
/// or outlives the wall time (plus a grace).
pub fn run(root: &Path, config: &Config) -> Result<Vec<Event>> {
    // The configuration goes in a file: a run of a thousand scripted
    // chunks is more than a command line may carry.
    static RUNS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let file = std::env::temp_dir().join(format!("idle-head-sim-{}-{n}.json", std::process::id()));
    std::fs::write(&file, config.json().to_string())
        .with_context(|| format!("writing {}", file.display()))?;
    let events = run_with_file(root, config, &file);
    let _ = std::fs::remove_file(&file);
    events
}

/// [`run`], its configuration in `file`.
fn run_with_file(root: &Path, config: &Config, file: &Path) -> Result<Vec<Event>> {
    let mut command = Command::new("node");
    command
        .arg("harness.mjs")
        .arg(format!("@{}", file.display()))
        .current_dir(folder(root))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let child = command
        .spawn()
        .context("could not start `node` (is Node.js installed?)")?;
    // The harness stops itself at `wall`; the grace covers node's start-up.
    let limit = config.wall + GRACE;
    let done = project::finish(child, "node", limit, events, read_all, || ())?;
    let status = match done.exit {
        Exit::Status(status) => status,
        Exit::TimedOut(_) => bail!(
            "the emulator made no progress: node was killed after {} s of wall time",
            limit.as_secs()
        ),
    };
    let events = done.stdout?;
    if !status.success() && !matches!(events.last(), Some(Event::End { .. })) {
        bail!(
            "the emulator harness failed ({status}):\n{}",
            done.stderr.trim_end()
        );
    }
    Ok(events)
}

/// Wall time the harness has beyond its own limit: node's start-up.
const GRACE: Duration = Duration::from_secs(15);

/// The harness's events, one JSON line each, read to the end of its output
/// (also past a bad line, so that node never waits on a full pipe); the
/// first line that is not a known event is the error.
fn events(stdout: impl Read) -> Result<Vec<Event>> {
    let mut events = Vec::new();
    let mut bad = None;
    for line in BufReader::new(stdout).lines() {
        let line = line.context("reading the harness's output")?;
        match Event::parse(&line) {
            Ok(event) => events.push(event),
            Err(e) => {
                bad.get_or_insert(e);
            }
        }
    }
    bad.map_or(Ok(events), Err)
}

/// All of `stderr`, as text.
fn read_all(mut stderr: impl Read) -> String {
    let mut bytes = Vec::new();
    let _ = stderr.read_to_end(&mut bytes);
    String::from_utf8_lossy(&bytes).into_owned()
}
