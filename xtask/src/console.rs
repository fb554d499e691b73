//! `cargo xtask console`: talk to a head, lines from stdin, replies to
//! stdout, one per line. `--qemu` runs the firmware in QEMU with its UART0
//! on a socket; `--port` opens a serial port; with neither, the Pico is
//! found by its USB VID:PID. Also the flood and console stages of `cargo
//! xtask test`.

use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use defmt_decoder::Table;

use crate::child;
use crate::log::Run;
use crate::qemu::{self, Echo};
use crate::{project, setup};

/// The Pico's USB vendor and product ID: the V-USB shared pair for
/// CDC-ACM serial devices (0x16c0:0x27dd), free for hobby devices that
/// are told apart by their strings.
pub const PICO_USB_ID: (u16, u16) = (
    idle_head_core::console::usb_identity::VID,
    idle_head_core::console::usb_identity::PID,
);

/// `cargo xtask console` options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Run the firmware in QEMU and talk to its UART0; when stdin closes,
    /// stop it and print its summary line.
    #[arg(long, conflicts_with = "port")]
    pub qemu: bool,
    /// The serial port of the head (115200 8N1), e.g. /dev/ttyACM0.
    /// Without it (and without --qemu) the Pico is found by its USB
    /// VID:PID 16c0:27dd.
    #[arg(long, value_name = "dev")]
    pub port: Option<PathBuf>,
    /// Seconds to wait for the replies still due once stdin has closed.
    #[arg(long, value_name = "s", default_value_t = 10)]
    pub wait: u64,
}

/// `cargo xtask console`.
pub fn command(args: &Args) -> Result<bool> {
    let stdin = std::io::stdin().lock();
    let mut stdout = std::io::stdout();
    let wait = Duration::from_secs(args.wait);
    if args.qemu {
        let root = project::root();
        setup::ensure_toolchain(&root)?;
        setup::ensure_qemu()?;
        let metadata = project::metadata(&root)?;
        project::QEMU.build(&root)?;
        eprintln!("console: QEMU running; type commands, end with Ctrl-D");
        let session = qemu_session(
            &project::QEMU.elf(&metadata),
            stdin.lines().map_while(Result::ok),
            |reply| {
                let _ = writeln!(stdout, "{reply}");
                let _ = stdout.flush();
            },
            Pace::RealTime,
            Echo::Quiet,
            wait,
        )?;
        // The firmware's warnings and errors on stderr: stdout has the
        // replies and the summary only.
        for line in session.run.log.iter().filter(|l| l.is_problem()) {
            eprintln!("{}", line.snapshot());
        }
        match session.summary() {
            Some(line) => println!("{line}"),
            None => println!("no summary line: {}", session.run.describe()),
        }
        return Ok(session.run.succeeded() && session.missing == 0);
    }
    let port = match &args.port {
        Some(port) => port.clone(),
        None => find_pico()?,
    };
    serial_session(&port, stdin, &mut stdout, wait)
}

/// The product string the head's USB port reports.
pub const PICO_PRODUCT: &str = idle_head_core::console::usb_identity::PRODUCT;

/// The Pico's port: the USB serial device with [`PICO_USB_ID`] and
/// [`PICO_PRODUCT`] (see [`pick_pico`]).
fn find_pico() -> Result<PathBuf> {
    let ports = serialport::available_ports().context("listing serial ports")?;
    pick_pico(&ports)
}

/// The head among `ports`. Other hobby devices share [`PICO_USB_ID`], so
/// the product string decides: the one port with [`PICO_USB_ID`] and
/// [`PICO_PRODUCT`]; failing that, the one port with [`PICO_USB_ID`] whose
/// strings the system does not show. None, or more than one, is an error
/// that lists what was found and asks for `--port`.
fn pick_pico(ports: &[serialport::SerialPortInfo]) -> Result<PathBuf> {
    let shared: Vec<(&str, Option<&str>)> = ports
        .iter()
        .filter_map(|p| match &p.port_type {
            serialport::SerialPortType::UsbPort(usb) if (usb.vid, usb.pid) == PICO_USB_ID => {
                Some((p.port_name.as_str(), usb.product.as_deref()))
            }
            _ => None,
        })
        .collect();
    let heads: Vec<&str> = shared
        .iter()
        .filter(|(_, product)| *product == Some(PICO_PRODUCT))
        .map(|(name, _)| *name)
        .collect();
    let unnamed: Vec<&str> = shared
        .iter()
        .filter(|(_, product)| product.is_none())
        .map(|(name, _)| *name)
        .collect();
    let (vid, pid) = PICO_USB_ID;
    match (heads.as_slice(), unnamed.as_slice()) {
        ([one], _) | ([], [one]) => Ok(PathBuf::from(one)),
        ([], []) if shared.is_empty() => bail!(
            "no USB serial device {vid:04x}:{pid:04x} found; is the head plugged in, \
             running the console image (--features console)? (or give --port <dev>)"
        ),
        ([], []) => bail!(
            "no head among the USB serial devices {vid:04x}:{pid:04x}: {}; give --port <dev>",
            shared
                .iter()
                .map(|(name, product)| format!("{name} (\"{}\")", product.unwrap_or_default()))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        (several, _) if several.len() > 1 => bail!(
            "several heads ({vid:04x}:{pid:04x} \"{PICO_PRODUCT}\"): {}; give --port <dev>",
            several.join(", ")
        ),
        (_, several) => bail!(
            "several USB serial devices {vid:04x}:{pid:04x} without a product string: {}; \
             give --port <dev>",
            several.join(", ")
        ),
    }
}

/// Lines from `input` to the port, replies to `out`, one per line.
fn serial_session(
    port: &Path,
    input: impl BufRead,
    out: &mut impl Write,
    wait: Duration,
) -> Result<bool> {
    let name = port.to_string_lossy();
    let mut serial = serialport::new(name.as_ref(), 115_200)
        .data_bits(serialport::DataBits::Eight)
        .parity(serialport::Parity::None)
        .stop_bits(serialport::StopBits::One)
        .timeout(Duration::from_millis(100))
        .open()
        .with_context(|| format!("opening {name}"))?;
    let reader = serial.try_clone().context("a second handle on the port")?;
    let (tx, rx) = mpsc::channel();
    thread::spawn(move || read_replies(reader, |reply| tx.send(reply).is_ok()));
    let mut sent = 0_usize;
    let mut got = 0_usize;
    for line in input.lines() {
        let line = line.context("reading stdin")?;
        serial.write_all(line.as_bytes())?;
        serial.write_all(b"\n")?;
        sent += 1;
        while let Ok(reply) = rx.try_recv() {
            writeln!(out, "{reply}")?;
            got += 1;
        }
    }
    let deadline = Instant::now() + wait;
    while got < sent {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(reply) => {
                writeln!(out, "{reply}")?;
                got += 1;
            }
            Err(_) => break,
        }
    }
    if got < sent {
        eprintln!("console: {} of {sent} lines got no reply", sent - got);
    }
    Ok(got == sent)
}

/// Splits `reader`'s bytes into reply lines (CR LF), handed to `each`
/// until it returns `false` or the stream ends.
fn read_replies(mut reader: impl Read, mut each: impl FnMut(String) -> bool) {
    let mut line = Vec::new();
    let mut buf = [0_u8; 4096];
    loop {
        match reader.read(&mut buf) {
            Ok(0) => return,
            Ok(n) => {
                for &b in &buf[..n] {
                    if b == b'\n' {
                        if line.last() == Some(&b'\r') {
                            line.pop();
                        }
                        if !each(String::from_utf8_lossy(&line).into_owned()) {
                            return;
                        }
                        line.clear();
                    } else {
                        line.push(b);
                    }
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(_) => return,
        }
    }
}

/// How QEMU's virtual clock runs while the core sleeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pace {
    /// With the wall clock (`sleep=on`): for a person at the console.
    RealTime,
    /// Jumping over idle time (`sleep=off`): as fast as the host can.
    Fast,
}

/// A QEMU run with its console.
pub struct QemuSession {
    /// The firmware's log and exit.
    pub run: Run,
    /// Lines sent.
    pub sent: usize,
    /// Replies received.
    pub replies: usize,
    /// Lines that got no reply before the hang-up.
    pub missing: usize,
    /// Wall time from the first line sent to the last reply.
    pub talk_time: Duration,
}

impl QemuSession {
    /// The firmware's summary line.
    pub fn summary(&self) -> Option<String> {
        self.run
            .log
            .iter()
            .rev()
            .find(|line| line.message.starts_with("summary"))
            .map(|line| line.message.clone())
    }
}

/// Runs `elf` in QEMU held for its console (semihosting argument
/// `console`): sends `lines` to UART0, hands each reply to `on_reply`,
/// waits up to `wait` for the replies still due, then hangs up (a byte on
/// UART1), so that the firmware fades out and prints its summary.
pub fn qemu_session(
    elf: &Path,
    lines: impl Iterator<Item = String>,
    mut on_reply: impl FnMut(&str) + Send,
    pace: Pace,
    echo: Echo,
    wait: Duration,
) -> Result<QemuSession> {
    let root = project::root();
    let bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let table = Table::parse(&bytes)?.context("no defmt data in the image")?;
    let locations = table.get_locations(&bytes).ok();
    let dir = std::env::temp_dir().join(format!("idle-head-console-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let [uart0, uart1] = ["uart0", "uart1"].map(|n| dir.join(format!("{n}.sock")));
    for path in [&uart0, &uart1] {
        let _ = std::fs::remove_file(path);
    }
    let sleep = match pace {
        Pace::RealTime => "on",
        Pace::Fast => "off",
    };
    let child = Command::new(setup::QEMU_BINARY)
        .args([
            "-machine",
            "lm3s6965evb",
            "-cpu",
            "cortex-m0",
            "-display",
            "none",
        ])
        .args(["-monitor", "none"])
        .args([
            "-semihosting-config",
            "enable=on,target=native,arg=idle-head,arg=console",
        ])
        .args(["-icount", &format!("shift=0,sleep={sleep}")])
        .arg("-serial")
        .arg(format!("unix:{},server=on,wait=on", uart0.display()))
        .arg("-serial")
        .arg(format!("unix:{},server=on,wait=on", uart1.display()))
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("could not start {}", setup::QEMU_BINARY))?;
    let start = Instant::now();
    let done = child::run(
        child,
        setup::QEMU_BINARY,
        Duration::from_secs(120),
        |stdout| qemu::decode(stdout, &table, locations.as_ref(), &root, echo),
        |stderr| {
            // QEMU says it waits for each socket's connection: not news here.
            let mut to = std::io::stderr();
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                if !line.contains("QEMU waiting for connection") && !qemu::is_reset_noise(&line) {
                    let _ = writeln!(to, "{line}");
                }
            }
        },
        || talk(&uart0, &uart1, lines, &mut on_reply, wait),
    )?;
    let _ = std::fs::remove_dir_all(&dir);
    let (sent, replies, talk_time) = done.meanwhile?;
    Ok(QemuSession {
        run: Run {
            log: done.stdout,
            exit: done.exit,
            elapsed: start.elapsed(),
        },
        sent,
        replies,
        missing: sent.saturating_sub(replies),
        talk_time,
    })
}

/// Connects to a socket QEMU serves, waiting for it to appear.
fn connect(path: &Path) -> Result<UnixStream> {
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

/// The conversation: this thread sends the lines, a reader thread hands
/// the replies to `on_reply` as they come; then the hang-up.
fn talk(
    uart0: &Path,
    uart1: &Path,
    lines: impl Iterator<Item = String>,
    on_reply: &mut (impl FnMut(&str) + Send),
    wait: Duration,
) -> Result<(usize, usize, Duration)> {
    let mut console = connect(uart0)?;
    let mut hangup = connect(uart1)?;
    let reader = console.try_clone()?;
    let replies = AtomicUsize::new(0);
    let start = Instant::now();
    let mut last_reply = start;
    thread::scope(|scope| -> Result<_> {
        let counter = &replies;
        let reading = scope.spawn(move || {
            let mut last = Instant::now();
            read_replies(reader, |reply| {
                on_reply(&reply);
                last = Instant::now();
                counter.fetch_add(1, Ordering::AcqRel);
                true
            });
            last
        });
        let mut sent = 0_usize;
        for line in lines {
            console.write_all(line.as_bytes())?;
            console.write_all(b"\n")?;
            sent += 1;
        }
        console.flush()?;
        let deadline = Instant::now() + wait;
        while replies.load(Ordering::Acquire) < sent && Instant::now() < deadline {
            thread::sleep(Duration::from_millis(2));
        }
        // Hang up: the firmware fades out, prints its summary and exits,
        // which closes the socket and ends the reader.
        hangup.write_all(b"\0")?;
        if let Ok(last) = reading.join() {
            last_reply = last;
        }
        Ok((
            sent,
            replies.load(Ordering::Acquire),
            last_reply.saturating_duration_since(start),
        ))
    })
}

/// Lines the flood stage streams into the QEMU run.
pub const FLOOD_LINES: usize = 10_000;

/// The flood's lines: valid commands that do not move the head (the smoke
/// run's checks stay meaningful; motion is the host fuzz's), machine-mode
/// lines, and invalid lines of every kind; with the reply each must get
/// (`ok` or `err <code>` prefix, or `#` for machine mode).
fn flood_lines() -> Vec<(String, &'static str)> {
    const KINDS: [(&str, &str); 14] = [
        ("status", "ok mode="),
        ("help", "ok commands:"),
        ("servo pitch", "ok pitch neutral="),
        ("SERVO Yaw", "ok yaw neutral="),
        ("nodd", "err syntax "),
        ("idle amp 150", "err range "),
        ("look 5000", "err syntax "),
        ("servo neck neutral 1500", "err syntax "),
        ("servo roll min 2600", "err invalid "),
        ("nod 6k", "err syntax "),
        ("", "err syntax "),
        ("status \u{1b}[A", "err line "),
        ("#7 status *00", "#7 err line "),
        ("#12 status", "#12 err line "),
    ];
    let overlong = "x".repeat(120);
    (0..FLOOD_LINES)
        .map(|i| match i % 17 {
            15 => (overlong.clone(), "err line "),
            16 => {
                let body = format!("#{i} status");
                let crc = crc8(body.as_bytes());
                (format!("{body} *{crc:02x}"), "#")
            }
            k => {
                let (line, reply) = KINDS[k % KINDS.len()];
                (line.to_owned(), reply)
            }
        })
        .collect()
}

/// CRC-8/SMBUS, as machine mode checks it.
fn crc8(bytes: &[u8]) -> u8 {
    bytes.iter().fold(0_u8, |mut crc, &b| {
        crc ^= b;
        for _ in 0..8 {
            crc = if crc & 0x80 != 0 {
                crc << 1 ^ 0x07
            } else {
                crc << 1
            };
        }
        crc
    })
}

/// The flood stage: [`FLOOD_LINES`] lines into a QEMU run as fast as it
/// takes them; exactly one reply per line, each the one expected, and the
/// summary still `missed=0 pulse_violations=0` with the host's checksum.
pub fn flood(elf: &Path) -> Result<String> {
    let lines = flood_lines();
    let expected: Vec<&str> = lines.iter().map(|(_, want)| *want).collect();
    let mut replies = Vec::with_capacity(FLOOD_LINES);
    let session = qemu_session(
        elf,
        lines.into_iter().map(|(line, _)| line),
        |reply| replies.push(reply.to_owned()),
        Pace::Fast,
        Echo::Problems,
        Duration::from_secs(60),
    )?;
    let summary = session.summary().unwrap_or_default();
    println!("{}", session.run.describe());
    println!("{summary}");
    if !session.run.succeeded() {
        bail!("the firmware failed: {}", session.run.describe());
    }
    if replies.len() != session.sent || session.replies != session.sent {
        bail!("{} lines sent, {} replies", session.sent, replies.len());
    }
    for (i, (reply, want)) in replies.iter().zip(&expected).enumerate() {
        if !reply.starts_with(want) {
            bail!("line {i}: reply {reply:?}, want one starting {want:?}");
        }
    }
    let verdict = qemu::check_summary(&session.run.log)?;
    if let Some(line) = session
        .run
        .log
        .iter()
        .find(|l| l.message.starts_with("console: the host hung up"))
    {
        println!("{}", line.message);
    }
    let frames = summary
        .split_whitespace()
        .find_map(|w| w.strip_prefix("frames="))
        .unwrap_or("?");
    Ok(format!(
        "flood: {} lines sent, {} replies (one each, as expected), in {:.2} s of wall time \
         ({:.2} s for the whole run, {frames} frames); {verdict}",
        session.sent,
        replies.len(),
        session.talk_time.as_secs_f64(),
        session.run.elapsed.as_secs_f64()
    ))
}

/// The console stage: `cargo xtask console --qemu` itself, a script piped
/// into its stdin; one reply per line on stdout, then the summary line.
pub fn piped_script() -> Result<String> {
    const SCRIPT: &str = "help\nstatus\nservo yaw\nservo yaw neutral 1520\nservo yaw\n\
                          idle amp 60\nseed 42\nsave\ndefaults\nload\nservo yaw\nnodd\n\
                          servo yaw min 2600\nstatus\n";
    const WANT: [&str; 14] = [
        "ok commands:",
        "ok mode=running",
        "ok yaw neutral=1500 ",
        "ok",
        "ok yaw neutral=1520 ",
        "ok",
        "ok seed=42",
        "ok",
        "ok",
        "ok",
        "ok yaw neutral=1520 ",
        "err syntax unknown command `nodd`",
        "err invalid yaw servo:",
        "ok mode=running",
    ];
    let exe = std::env::current_exe().context("the xtask's own path")?;
    let mut child = Command::new(exe)
        .args(["console", "--qemu"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .context("starting `cargo xtask console --qemu`")?;
    child
        .stdin
        .take()
        .context("its stdin")?
        .write_all(SCRIPT.as_bytes())?;
    let out = child.wait_with_output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    print!("{text}");
    if lines.len() != WANT.len() + 1 {
        bail!(
            "{} lines out for {} in, plus the summary",
            lines.len(),
            WANT.len()
        );
    }
    for (i, (got, want)) in lines.iter().zip(WANT).enumerate() {
        if !(got.starts_with(want) && (want != "ok" || *got == "ok")) {
            bail!("line {i}: {got:?}, want {want:?}");
        }
    }
    let summary = lines[WANT.len()];
    if !summary.starts_with("summary ") || !summary.contains(" missed=0 pulse_violations=0 ") {
        bail!("last line {summary:?}");
    }
    if !out.status.success() {
        bail!("`cargo xtask console --qemu` failed ({})", out.status);
    }
    Ok(format!(
        "console --qemu: {} lines, {} replies, then {summary}",
        WANT.len(),
        WANT.len()
    ))
}

#[cfg(test)]
mod port_tests;
