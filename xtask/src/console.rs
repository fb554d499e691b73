//! `cargo xtask console`: talk to a head, stdin to it and its replies to
//! stdout, one per line, the bytes unchanged both ways. `--qemu` runs the
//! firmware in QEMU, `--port` opens a serial port, neither finds the Pico
//! by its USB VID:PID. Also the console stage of `cargo xtask test`.

pub mod qemu;
mod stages;
mod talk;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result, bail};

pub use qemu::{Pace, qemu_session};
pub use stages::piped_script;
use talk::Talk;

use crate::qemu::Echo;
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
    let print = move |reply: &[u8]| {
        let _ = stdout.write_all(reply);
        let _ = stdout.write_all(b"\n");
        let _ = stdout.flush();
    };
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
            stdin,
            print,
            Pace::RealTime,
            Echo::Quiet,
            wait,
        )?;
        // The firmware's warnings and errors on stderr: stdout has the
        // replies and the summary only.
        for line in session.run.log.iter().filter(|l| l.is_problem()) {
            eprintln!("{}", line.snapshot());
        }
        let talked = said(&session.talk, "QEMU's UART0");
        match session.summary() {
            Some(line) => println!("{line}"),
            None => println!("no summary line: {}", session.run.describe()),
        }
        return Ok(session.run.succeeded() && talked);
    }
    let port = match &args.port {
        Some(port) => port.clone(),
        None => find_pico()?,
    };
    let talk = serial_session(&port, stdin, print, wait)?;
    Ok(said(&talk, &port.to_string_lossy()))
}

/// Says on stderr what went wrong in `talk` on `port`; whether nothing did.
fn said(talk: &Talk, port: &str) -> bool {
    let problems = talk.problems();
    for problem in &problems {
        eprintln!("console: {port}: {problem}");
    }
    problems.is_empty()
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
             running the firmware? (or give --port <dev>)"
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

/// The serial port at `path`, 115200 8N1, a read giving up after
/// `timeout`.
pub(crate) fn open_port(path: &Path, timeout: Duration) -> Result<Box<dyn serialport::SerialPort>> {
    let name = path.to_string_lossy();
    serialport::new(name.as_ref(), 115_200)
        .data_bits(serialport::DataBits::Eight)
        .parity(serialport::Parity::None)
        .stop_bits(serialport::StopBits::One)
        .timeout(timeout)
        .open()
        .with_context(|| format!("opening {name}"))
}

/// `input` to the port and its replies to `on_reply`, one line each
/// ([`talk::converse`]).
fn serial_session(
    port: &Path,
    input: impl std::io::Read,
    mut on_reply: impl FnMut(&[u8]) + Send,
    wait: Duration,
) -> Result<Talk> {
    let mut serial = open_port(port, Duration::from_millis(100))?;
    let reader = serial.try_clone().context("a second handle on the port")?;
    // The reader ends at its next read timeout once the session is over.
    Ok(talk::converse(
        input,
        &mut serial,
        reader,
        &mut on_reply,
        wait,
        || Ok(()),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A USB serial port as the system lists it.
    fn usb(name: &str, vid: u16, pid: u16, product: Option<&str>) -> serialport::SerialPortInfo {
        serialport::SerialPortInfo {
            port_name: name.to_owned(),
            port_type: serialport::SerialPortType::UsbPort(serialport::UsbPortInfo {
                vid,
                pid,
                serial_number: None,
                manufacturer: None,
                product: product.map(str::to_owned),
            }),
        }
    }

    #[test]
    fn the_head_is_found_by_its_id_and_product_among_other_devices() {
        let (vid, pid) = PICO_USB_ID;
        let other = usb("/dev/ttyACM0", vid, pid, Some("some other gadget"));
        let head = usb("/dev/ttyACM1", vid, pid, Some(PICO_PRODUCT));
        let arduino = usb("/dev/ttyACM2", 0x2341, 0x0043, Some(PICO_PRODUCT));
        let pty = serialport::SerialPortInfo {
            port_name: "/dev/pts/3".to_owned(),
            port_type: serialport::SerialPortType::Unknown,
        };
        let found = pick_pico(&[other.clone(), arduino.clone(), head, pty.clone()]);
        assert_eq!(found.unwrap(), PathBuf::from("/dev/ttyACM1"));

        // The shared ID alone is not enough when the product says otherwise.
        let err = pick_pico(&[other.clone(), arduino.clone(), pty]).unwrap_err();
        assert!(
            err.to_string()
                .contains("/dev/ttyACM0 (\"some other gadget\")"),
            "{err}"
        );
        let err = pick_pico(&[arduino]).unwrap_err();
        assert!(err.to_string().contains("is the head plugged in"), "{err}");

        // Without product strings, one device of the ID is taken; two are not.
        let bare = usb("/dev/ttyACM4", vid, pid, None);
        assert_eq!(
            pick_pico(&[other, bare.clone()]).unwrap(),
            PathBuf::from("/dev/ttyACM4")
        );
        let bare2 = usb("/dev/ttyACM5", vid, pid, None);
        let err = pick_pico(&[bare, bare2]).unwrap_err();
        assert!(
            err.to_string().contains("without a product string"),
            "{err}"
        );
    }

    #[test]
    fn two_heads_need_a_port() {
        let (vid, pid) = PICO_USB_ID;
        let a = usb("/dev/ttyACM0", vid, pid, Some(PICO_PRODUCT));
        let b = usb("/dev/ttyACM1", vid, pid, Some(PICO_PRODUCT));
        let err = pick_pico(&[a, b]).unwrap_err();
        assert!(
            err.to_string()
                .contains("/dev/ttyACM0, /dev/ttyACM1; give --port"),
            "{err}"
        );
    }
}
