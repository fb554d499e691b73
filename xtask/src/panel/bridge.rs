//! The head behind the page's WebSocket: the emulated Pico, the QEMU
//! image or a serial port. Bytes go through as they are, both ways; what
//! the head sends is handed to every page connected ([`Hub`]).

use std::{
    io::{Read, Write},
    net::Shutdown,
    os::unix::net::UnixStream,
    path::{Path, PathBuf},
    process::{Child, Stdio},
    sync::{Arc, Mutex, mpsc},
    thread,
    time::Duration,
};

use anyhow::{Context, Result};

use crate::console::{
    Pace, open_port,
    qemu::{Sockets, connect, spawn_with_sockets},
};
use crate::sim::live::{self, LiveEvent};

/// What the head says, for each page connected.
#[derive(Debug, Clone)]
pub enum Note {
    /// Bytes from the head.
    Bytes(Vec<u8>),
    /// The head went away, and why.
    Gone(String),
}

/// The pages connected: each gets every [`Note`].
#[derive(Default)]
pub struct Hub {
    pages: Mutex<Vec<mpsc::Sender<Note>>>,
    gone: Mutex<Option<String>>,
}

impl Hub {
    /// A page joins.
    pub fn join(&self) -> mpsc::Receiver<Note> {
        let (tx, rx) = mpsc::channel();
        if let Some(why) = self.gone.lock().ok().and_then(|g| g.clone()) {
            let _ = tx.send(Note::Gone(why));
        }
        if let Ok(mut pages) = self.pages.lock() {
            pages.push(tx);
        }
        rx
    }

    fn tell(&self, note: &Note) {
        if let Note::Gone(why) = note
            && let Ok(mut gone) = self.gone.lock()
        {
            *gone = Some(why.clone());
        }
        if let Ok(mut pages) = self.pages.lock() {
            pages.retain(|page| page.send(note.clone()).is_ok());
        }
    }
}

/// A head, bridged: write to it, hear from it through the [`Hub`].
pub struct Bridge {
    /// What it is, for people (`the RP2040 emulator`, ...).
    pub name: String,
    /// Its short name for the page (`sim`, `qemu`, `port`).
    pub kind: &'static str,
    writer: Mutex<Box<dyn Write + Send>>,
    /// Who hears from it.
    pub hub: Arc<Hub>,
    /// What to stop when the bridge goes.
    child: Option<Child>,
    /// QEMU's hang-up line (UART1).
    hang_up: Option<UnixStream>,
    /// Where QEMU's sockets are.
    dir: Option<PathBuf>,
}

impl Bridge {
    /// Writes `bytes` to the head.
    ///
    /// # Errors
    /// The head's end is gone.
    pub fn write(&self, bytes: &[u8]) -> Result<()> {
        let mut writer = self
            .writer
            .lock()
            .map_err(|_| anyhow::anyhow!("the writer panicked"))?;
        writer.write_all(bytes)?;
        writer.flush()?;
        Ok(())
    }

    /// The shipped Pico image `elf` live in the RP2040 emulator, over its
    /// USB serial port.
    pub fn sim(root: &Path, elf: &Path) -> Result<Self> {
        let live = live::start(root, elf)?;
        let hub = Arc::new(Hub::default());
        let heard = Arc::clone(&hub);
        let stdout = live.stdout;
        thread::spawn(move || {
            live::events(stdout, |event| match event {
                LiveEvent::Bytes(bytes) => heard.tell(&Note::Bytes(bytes)),
                LiveEvent::End(why) => heard.tell(&Note::Gone(why)),
                LiveEvent::Connected => {}
            });
        });
        Ok(Self {
            name: "the shipped Pico image in the RP2040 emulator (USB serial port)".to_owned(),
            kind: "sim",
            writer: Mutex::new(Box::new(HexLines(live.stdin))),
            hub,
            child: Some(live.child),
            hang_up: None,
            dir: None,
        })
    }

    /// The QEMU image `elf`, a clean head at real time, over its UART0.
    pub fn qemu(elf: &Path) -> Result<Self> {
        let Sockets {
            child,
            dir,
            uart0,
            uart1,
        } = spawn_with_sockets(elf, Pace::RealTime, "panel", Stdio::null)?;
        let console = connect(&uart0)?;
        let hang_up = connect(&uart1)?;
        let reader = console.try_clone()?;
        let hub = Arc::new(Hub::default());
        spawn_reader(reader, Arc::clone(&hub), "QEMU's UART0 closed");
        Ok(Self {
            name: "the QEMU image (UART0)".to_owned(),
            kind: "qemu",
            writer: Mutex::new(Box::new(console)),
            hub,
            child: Some(child),
            hang_up: Some(hang_up),
            dir: Some(dir),
        })
    }

    /// A board's serial port at 115200 8N1.
    pub fn port(port: &Path) -> Result<Self> {
        let name = port.to_string_lossy().into_owned();
        let serial = open_port(port, Duration::from_secs(3600))?;
        let reader = serial.try_clone().context("a second handle on the port")?;
        let hub = Arc::new(Hub::default());
        spawn_reader(reader, Arc::clone(&hub), "the serial port closed");
        Ok(Self {
            name: format!("the serial port {name}"),
            kind: "port",
            writer: Mutex::new(Box::new(serial)),
            hub,
            child: None,
            hang_up: None,
            dir: None,
        })
    }
}

impl Drop for Bridge {
    fn drop(&mut self) {
        // QEMU: hang up, so that the image plays what is queued and exits.
        if let Some(mut hang_up) = self.hang_up.take() {
            let _ = hang_up.write_all(b"\0");
            let _ = hang_up.shutdown(Shutdown::Write);
        }
        if let Some(mut child) = self.child.take() {
            let deadline = std::time::Instant::now() + Duration::from_secs(3);
            while std::time::Instant::now() < deadline {
                if matches!(child.try_wait(), Ok(Some(_))) {
                    break;
                }
                // The emulator ends when its stdin closes.
                if let Ok(mut writer) = self.writer.lock() {
                    *writer = Box::new(std::io::sink());
                }
                thread::sleep(Duration::from_millis(20));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        if let Some(dir) = self.dir.take() {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

/// Reads `reader` on a thread of its own, telling `hub` what comes, then
/// that it ended (`why`, or the read error).
fn spawn_reader(mut reader: impl Read + Send + 'static, hub: Arc<Hub>, why: &'static str) {
    thread::spawn(move || {
        let mut buf = [0_u8; 4096];
        loop {
            match reader.read(&mut buf) {
                Ok(0) => {
                    hub.tell(&Note::Gone(why.to_owned()));
                    return;
                }
                Ok(n) => hub.tell(&Note::Bytes(buf[..n].to_vec())),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                Err(e) => {
                    hub.tell(&Note::Gone(format!("{why}: {e}")));
                    return;
                }
            }
        }
    });
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
