//! The head behind the page's bridge: the emulated Pico, the QEMU image or
//! a serial port. Bytes go through as they are, both ways; what the head
//! sends goes to every page connected.

use std::{
    io::{ErrorKind, Read, Write},
    net::{Shutdown, TcpStream},
    path::Path,
    process::{Child, Stdio},
    sync::{Mutex, mpsc},
    thread,
    time::Duration,
};

use anyhow::{Context, Result, anyhow};
use wait_timeout::ChildExt;

use crate::console::{Pace, open_port, qemu::spawn_connected};
use crate::sim::live;

/// What the head says, for each page connected.
#[derive(Debug, Clone)]
pub enum Note {
    Bytes(Vec<u8>),
    /// The head went away, and why.
    Gone(String),
}

/// The pages connected, each told every [`Note`]; and why the head went
/// away, once it has (a page that joins later is told at once).
#[derive(Default)]
pub struct Hub(Mutex<(Vec<mpsc::Sender<Note>>, Option<String>)>);

impl Hub {
    pub fn join(&self) -> mpsc::Receiver<Note> {
        let (tx, rx) = mpsc::channel();
        if let Ok(mut hub) = self.0.lock() {
            if let Some(why) = &hub.1 {
                let _ = tx.send(Note::Gone(why.clone()));
            }
            hub.0.push(tx);
        }
        rx
    }

    fn tell(&self, note: &Note) {
        if let Ok(mut hub) = self.0.lock() {
            if let Note::Gone(why) = note {
                hub.1.get_or_insert_with(|| why.clone());
            }
            hub.0.retain(|page| page.send(note.clone()).is_ok());
        }
    }
}

/// A head, bridged: write to it, hear from it through its [`Hub`].
pub struct Bridge {
    /// What it is, for people.
    pub name: String,
    /// Its short name for the page (`sim`, `qemu`, `port`).
    pub kind: &'static str,
    pub hub: std::sync::Arc<Hub>,
    writer: Mutex<Box<dyn Write + Send>>,
    /// What to stop when the bridge goes: a process, QEMU's hang-up line
    /// (UART1).
    child: Option<Child>,
    hang_up: Option<TcpStream>,
}

impl Bridge {
    fn new(name: impl Into<String>, kind: &'static str, writer: Box<dyn Write + Send>) -> Self {
        Self {
            name: name.into(),
            kind,
            hub: std::sync::Arc::default(),
            writer: Mutex::new(writer),
            child: None,
            hang_up: None,
        }
    }

    pub fn write(&self, bytes: &[u8]) -> Result<()> {
        let writer = self.writer.lock();
        let mut writer = writer.map_err(|_| anyhow!("the writer panicked"))?;
        writer.write_all(bytes)?;
        Ok(writer.flush()?)
    }

    /// The shipped Pico image `elf` live in the RP2040 emulator, over its
    /// USB serial port.
    pub fn sim(root: &Path, elf: &Path) -> Result<Self> {
        let mut child = live::start(root, elf)?;
        let pipes = child.stdin.take().zip(child.stdout.take());
        let (stdin, stdout) = pipes.context("the harness's stdin and stdout")?;
        let name = "the shipped Pico image in the RP2040 emulator (USB serial port)";
        let mut bridge = Self::new(name, "sim", Box::new(HexLines(stdin)));
        bridge.child = Some(child);
        let hub = std::sync::Arc::clone(&bridge.hub);
        thread::spawn(move || {
            let why = live::events(stdout, |bytes| hub.tell(&Note::Bytes(bytes)));
            hub.tell(&Note::Gone(why));
        });
        Ok(bridge)
    }

    /// The QEMU image `elf`, a clean head at real time, over its UART0.
    pub fn qemu(elf: &Path) -> Result<Self> {
        let (child, [console, hang_up]) = spawn_connected(elf, Pace::RealTime, Stdio::null)?;
        let reader = console.try_clone()?;
        let mut bridge = Self::new("the QEMU image (UART0)", "qemu", Box::new(console));
        (bridge.child, bridge.hang_up) = (Some(child), Some(hang_up));
        bridge.read(reader, "QEMU's UART0 closed");
        Ok(bridge)
    }

    /// A board's serial port at 115200 8N1.
    pub fn port(port: &Path) -> Result<Self> {
        let serial = open_port(port, Duration::from_secs(3600))?;
        let reader = serial.try_clone().context("a second handle on the port")?;
        let name = format!("the serial port {}", port.display());
        let bridge = Self::new(name, "port", Box::new(serial));
        bridge.read(reader, "the serial port closed");
        Ok(bridge)
    }

    /// Reads `reader` on a thread of its own, telling the hub what comes,
    /// then that it ended (`why`, or the read error).
    fn read(&self, mut reader: impl Read + Send + 'static, why: &'static str) {
        let hub = std::sync::Arc::clone(&self.hub);
        thread::spawn(move || {
            let mut buf = [0_u8; 4096];
            let why = loop {
                match reader.read(&mut buf) {
                    Ok(0) => break why.to_owned(),
                    Ok(n) => hub.tell(&Note::Bytes(buf[..n].to_vec())),
                    Err(e) if matches!(e.kind(), ErrorKind::Interrupted | ErrorKind::TimedOut) => {}
                    Err(e) => break format!("{why}: {e}"),
                }
            };
            hub.tell(&Note::Gone(why));
        });
    }
}

impl Drop for Bridge {
    fn drop(&mut self) {
        self.hub.tell(&Note::Gone("the bridge stopped".to_owned()));
        // QEMU: hang up, so that the image plays what is queued and exits;
        // the emulator ends when its stdin closes.
        if let Some(mut hang_up) = self.hang_up.take() {
            let _ = hang_up.write_all(b"\0");
            let _ = hang_up.shutdown(Shutdown::Write);
        }
        if let Ok(mut writer) = self.writer.lock() {
            *writer = Box::new(std::io::sink());
        }
        if let Some(mut child) = self.child.take() {
            let _ = child.wait_timeout(Duration::from_secs(3));
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// The emulator's stdin: bytes as lines of hex digits.
struct HexLines<W>(W);

impl<W: Write> Write for HexLines<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        live::send(&mut self.0, buf)?;
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
    }
}
