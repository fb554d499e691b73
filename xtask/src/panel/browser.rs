//! The panel's browser tests: headless Chromium driven by playwright-core
//! (`panel/tests/browser.mjs`) over each way to reach a head. Screenshots:
//! `target/panel/`.

use std::{
    io::{BufRead, BufReader, Write},
    net::TcpStream,
    path::{Path, PathBuf},
    process::{Child, Command, Stdio},
    sync::mpsc,
    time::{Duration, Instant},
};

use anyhow::{Context, Result, anyhow, bail};
use serde_json::{Value, json};

use super::{Bridge, ensure_dependencies, server::Server};
use crate::console::{self, Pace, qemu::qemu_command};
use crate::project::{Metadata, PICO, QEMU};
use crate::{project, qemu, setup, sim, trace};

pub const STAGE: &str = "panel in a real browser: Web Serial (emulated Pico), bridge (QEMU), serial port (pty), radar map (replay)";

/// Debian's Chromium.
const CHROMIUM: &str = "/usr/bin/chromium";

/// The stage: every session, then a summary line of what it measured.
pub fn stage(root: &Path, metadata: &Metadata) -> Result<()> {
    let start = Instant::now();
    setup::ensure_program(CHROMIUM, &["chromium"], "Chromium")?;
    ensure_dependencies(root)?;
    setup::ensure_qemu()?;
    PICO.build(root)?;
    QEMU.build(root)?;
    let shots = metadata.target_dir.join("panel");
    let harness = sim::live::config(root, &PICO.elf(metadata))?;
    let harness = json!({ "cwd": sim::node_folder(root), "arg": harness.to_string() });
    let serial = json!({ "session": "serial", "label": "web-serial", "harness": harness });
    let qemu = json!({ "session": "bridge", "label": "qemu" });
    // The emulated Pico's session beside the two short ones: a session
    // keeps about one core busy. The QEMU bridge's then runs alone: QEMU
    // keeps real time less well than the emulator does when the cores are
    // busy, and the head's glide to rest is timed.
    let (elf, mut report) = (QEMU.elf(metadata), Vec::new());
    std::thread::scope(|scope| {
        let short = scope.spawn(|| -> Result<[String; 2]> {
            Ok([serial_port(root, &elf, &shots)?, replay(root, &shots)?])
        });
        report.push(session(root, &shots, None, serial)?);
        let short = short
            .join()
            .map_err(|_| anyhow!("a browser session panicked"))?;
        report.extend(short?);
        Ok::<_, anyhow::Error>(())
    })?;
    report.push(session(root, &shots, Some(Bridge::qemu(&elf)?), qemu)?);
    let seconds = start.elapsed().as_secs_f64();
    println!("{}; {seconds:.0} s", report.join("; "));
    Ok(())
}

/// Serves the page, bridged to `bridge` if given, and runs one browser
/// session on it (`config`, for `panel/tests/browser.mjs`); its last line.
fn session(root: &Path, shots: &Path, bridge: Option<Bridge>, mut config: Value) -> Result<String> {
    let (stop, _) = mpsc::channel();
    let server = Server::start(root, "127.0.0.1:0".parse()?, bridge, stop)?;
    config["url"] = json!(format!("http://{}/", server.address));
    config["chromium"] = json!(CHROMIUM);
    config["shots"] = json!(shots);
    let mut node = Command::new("node");
    node.args(["tests/browser.mjs", &config.to_string()]);
    let (text, status) = project::output(node.current_dir(root.join("panel")), b"")?;
    let label = &config["label"];
    if !status.success() {
        let why = text.lines().rfind(|l| l.starts_with("FAILED"));
        bail!("browser session {label}: {}", why.unwrap_or("failed"));
    }
    let nod = text
        .lines()
        .rfind(|l| l.contains("Nod: the pitch readout swung"));
    Ok(nod.map_or_else(|| format!("{label} passed"), |l| format!("{label}: {l}")))
}

/// The lines the page sends as it connects and every 2 s after: their
/// replies are the console's, at the end of the replayed run.
const PAGE_ASKS: &str = "help|status|servo pitch|servo roll|servo yaw|servo rate|rest after|idle|\
                         look duck|seed|input 2|input 3|input 4|input 5|dmx|radar|track|watch 20";

/// The radar's map: the host trace of `panel/tests/radar-replay.txt`, its
/// telemetry replayed by a fake serial port that answers the page's lines
/// with the console's replies at the end of the run.
fn replay(root: &Path, shots: &Path) -> Result<String> {
    let path = root.join("panel/tests/radar-replay.txt");
    let script =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let events = sim::parse_script(&script)?;
    let end = events.last().map_or(0, |e| e.at_us) + 1_500_000;
    let asks: Vec<&str> = PAGE_ASKS.split('|').collect();
    let rate = idle_head_core::servo::ServoRate::DEFAULT;
    let run = trace::simulate(end, None, rate, &events, Some(20), &asks)?;
    let lines = run.watch.map(|w| w.lines).unwrap_or_default();
    let answers: serde_json::Map<String, Value> = asks
        .iter()
        .zip(run.answers)
        .map(|(ask, reply)| ((*ask).to_owned(), reply.into()))
        .collect();
    let replay = json!({ "lines": lines, "answers": answers });
    let config = json!({ "session": "replay", "label": "radar-replay", "replay": replay });
    session(root, shots, None, config)
}

/// QEMU with UART0 on a pseudo-terminal: `cargo xtask console --port` with
/// a piped script, then the panel bridged to it (`panel --port`).
fn serial_port(root: &Path, elf: &Path, shots: &Path) -> Result<String> {
    let (_qemu, path) = Pty::start(elf)?;
    let pty = path.display().to_string();
    println!("QEMU's UART0 is {pty}");
    let want =
        "ok commands:|ok mode=|ok nod amp_mdeg=|err invalid yaw servo: max_pulse 3000|ok watch=off";
    let want: Vec<&str> = want.split('|').collect();
    let script = b"help\nstatus\nnod\nservo yaw max 3000\nwatch off\n";
    console::script(&["--port", &pty], script, &want, 0)?;
    let config = json!({ "session": "bridge", "label": "serial-port" });
    let session = session(root, shots, Some(Bridge::port(&path)?), config)?;
    let n = want.len();
    Ok(format!(
        "console --port {pty}: {n} replies as expected; {session}"
    ))
}

/// QEMU, its UART0 on a pseudo-terminal, UART1 nowhere (no hang-up: it is
/// stopped when dropped).
struct Pty(Child);

impl Pty {
    /// Starts QEMU and asks its QMP monitor where the pseudo-terminal is
    /// (this QEMU writes no message saying so, and cannot link it to a
    /// path of our choosing). QEMU, and the pseudo-terminal's path.
    fn start(elf: &Path) -> Result<(Self, PathBuf)> {
        let qmp = console::qemu::listen()?;
        let monitor = format!("tcp:{}", qmp.local_addr()?);
        let mut command = qemu_command(elf, Pace::RealTime, ["pty", "null"]);
        // Dropped on an error: QEMU is stopped.
        let mut pty = Self(qemu::spawn(command.args(["-qmp", &monitor]), Stdio::null)?);
        let path = pty_path(console::qemu::accept(&qmp, &mut pty.0)?)?;
        Ok((pty, path))
    }
}

/// The pseudo-terminal of QEMU's `serial0`, from its QMP monitor on
/// `stream` (`query-chardev`: `"filename": "pty:/dev/pts/N"`).
fn pty_path(stream: TcpStream) -> Result<PathBuf> {
    stream.set_read_timeout(Some(Duration::from_secs(10)))?;
    (&stream)
        .write_all(b"{\"execute\":\"qmp_capabilities\"}\n{\"execute\":\"query-chardev\"}\n")?;
    for line in BufReader::new(stream).lines() {
        let reply: Value = serde_json::from_str(&line?)?;
        // The replies without a `return` list (the greeting, events) pass.
        if let Some(file) = (reply["return"].as_array().into_iter().flatten())
            .filter(|d| d["label"] == "serial0")
            .find_map(|d| d["filename"].as_str()?.strip_prefix("pty:"))
        {
            return Ok(PathBuf::from(file));
        }
    }
    bail!("QEMU's monitor did not say where its pseudo-terminal is")
}

impl Drop for Pty {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}
