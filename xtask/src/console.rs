//! `cargo xtask console`: stdin to a head (QEMU, a serial port, or the
//! Pico found by its USB VID:PID), its replies to stdout, bytes unchanged.

pub mod qemu;
mod stages;
mod talk;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use idle_head_core::console::usb_identity::{PID, PRODUCT, VID};

pub use qemu::{Pace, qemu_session};
pub use stages::{piped_script, script};

use crate::qemu::Echo;
use crate::{log, project, setup};

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

/// `cargo xtask console`. What ends a session early is said on stderr.
pub fn command(args: &Args) -> Result<bool> {
    let stdin = std::io::stdin().lock();
    let mut stdout = std::io::stdout();
    let mut print = move |reply: &[u8]| {
        let _ = stdout.write_all(reply);
        let _ = stdout.write_all(b"\n");
        let _ = stdout.flush();
    };
    let wait = Duration::from_secs(args.wait);
    let (talk, port, ran) = if args.qemu {
        let (root, metadata) = setup::prepare()?;
        setup::ensure_qemu()?;
        project::QEMU.build(&root)?;
        eprintln!("console: QEMU running; type commands, end with Ctrl-D");
        let elf = project::QEMU.elf(&metadata);
        let (run, talk) = qemu_session(&elf, stdin, &mut print, Pace::RealTime, Echo::Quiet, wait)?;
        // stdout has the replies and the summary only.
        for line in run.log.iter().filter(|l| l.is_problem()) {
            eprintln!("{}", line.snapshot());
        }
        match log::summary(&run.log) {
            Some(line) => println!("{line}"),
            None => println!("no summary line: {}", run.describe()),
        }
        (talk, "QEMU's UART0".to_owned(), run.succeeded())
    } else {
        let port = match &args.port {
            Some(port) => port.clone(),
            None => pick_pico(&serialport::available_ports().context("listing serial ports")?)?,
        };
        let mut serial = open_port(&port, Duration::from_millis(100))?;
        let reader = serial.try_clone().context("a second handle on the port")?;
        // The reader ends at its next read timeout once the session is over.
        let talk = talk::converse(stdin, &mut serial, reader, &mut print, wait, || Ok(()));
        (talk, port.display().to_string(), true)
    };
    let problems = talk.problems();
    for problem in &problems {
        eprintln!("console: {port}: {problem}");
    }
    Ok(ran && problems.is_empty())
}

/// The head among `ports`: other devices share its VID:PID (V-USB's shared
/// pair for CDC-ACM), so the one with the head's product string, else the
/// one whose strings the system does not show; none, or several, is an
/// error listing what was found.
fn pick_pico(ports: &[serialport::SerialPortInfo]) -> Result<PathBuf> {
    let shared: Vec<(&str, Option<&str>)> = (ports.iter())
        .filter_map(|p| match &p.port_type {
            serialport::SerialPortType::UsbPort(usb) if (usb.vid, usb.pid) == (VID, PID) => {
                Some((p.port_name.as_str(), usb.product.as_deref()))
            }
            _ => None,
        })
        .collect();
    let with = |product: Option<&str>| -> Vec<&str> {
        shared
            .iter()
            .filter(|p| p.1 == product)
            .map(|p| p.0)
            .collect()
    };
    let (heads, unnamed) = (with(Some(PRODUCT)), with(None));
    let id = format!("{VID:04x}:{PID:04x}");
    match (heads.as_slice(), unnamed.as_slice()) {
        ([one], _) | ([], [one]) => Ok(PathBuf::from(one)),
        ([], []) if shared.is_empty() => bail!(
            "no USB serial device {id} found; is the head plugged in, running the firmware? \
             (or give --port <dev>)"
        ),
        ([], []) => {
            let found: Vec<String> = (shared.iter())
                .map(|(name, product)| format!("{name} (\"{}\")", product.unwrap_or_default()))
                .collect();
            bail!(
                "no head among the USB serial devices {id}: {}; give --port <dev>",
                found.join(", ")
            )
        }
        ([_, _, ..], _) => bail!(
            "several heads ({id} \"{PRODUCT}\"): {}; give --port <dev>",
            heads.join(", ")
        ),
        (_, several) => bail!(
            "several USB serial devices {id} without a product string: {}; give --port <dev>",
            several.join(", ")
        ),
    }
}

/// The serial port at `path`, 115200 8N1, reads timing out after `timeout`.
pub(crate) fn open_port(path: &Path, timeout: Duration) -> Result<Box<dyn serialport::SerialPort>> {
    let name = path.to_string_lossy();
    let port = serialport::new(name.as_ref(), 115_200).timeout(timeout);
    port.open().with_context(|| format!("opening {name}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_head_is_found_by_its_id_and_product_among_other_devices() {
        let pick = |ports: &[(&str, u16, Option<&str>)]| {
            let usb = |&(name, vid, product): &(&str, u16, Option<&str>)| {
                let usb = serialport::UsbPortInfo {
                    vid,
                    pid: PID,
                    serial_number: None,
                    manufacturer: None,
                    product: product.map(str::to_owned),
                };
                let port_type = serialport::SerialPortType::UsbPort(usb);
                serialport::SerialPortInfo {
                    port_name: name.to_owned(),
                    port_type,
                }
            };
            let ports: Vec<_> = ports.iter().map(usb).collect();
            pick_pico(&ports).map_err(|e| e.to_string())
        };
        let other = ("/dev/ttyACM0", VID, Some("some other gadget"));
        let head = ("/dev/ttyACM1", VID, Some(PRODUCT));
        let arduino = ("/dev/ttyACM2", 0x2341, Some(PRODUCT));
        let (bare, bare2) = (("/dev/ttyACM4", VID, None), ("/dev/ttyACM5", VID, None));
        let found = |name: &str| Ok(PathBuf::from(name));
        let fails = |ports: &[(&str, u16, Option<&str>)], says: &str| {
            let err = pick(ports).unwrap_err();
            assert!(err.contains(says), "{err}");
        };
        assert_eq!(pick(&[other, arduino, head]), found("/dev/ttyACM1"));
        // The shared ID alone is not enough when the product says otherwise.
        fails(&[other, arduino], "/dev/ttyACM0 (\"some other gadget\")");
        fails(&[arduino], "is the head plugged in");
        // Without product strings, one device of the ID is taken; two are not.
        assert_eq!(pick(&[other, bare]), found("/dev/ttyACM4"));
        fails(&[bare, bare2], "without a product string");
        fails(&[head, head], "/dev/ttyACM1, /dev/ttyACM1; give --port");
    }
}
