//! `--port`: the session over a real tty, a pseudo-terminal whose other
//! side is a simulated head running the firmware's own console (session,
//! parser and service) on the host; and without `--port`, which USB serial
//! device is taken for the head.

use std::os::fd::RawFd;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::Duration;

use idle_head_core::behaviour::CommandQueue;
use idle_head_core::console::{ConsoleLink, ConsoleService, Session};
use idle_head_core::driver::DriverConfig;
use idle_head_core::settings::{RamStorage, SETTINGS_BUFFER, Settings, SettingsSource};
use nix::pty::openpty;

use super::serial_session;

/// A head on the master side of a pty: every line in, the firmware's
/// replies out, until `stop`. Lines containing `mute` get no reply, so
/// that the session's count of missing replies can be checked.
fn head(master: RawFd, stop: &AtomicBool) {
    static QUEUE: CommandQueue = CommandQueue::new();
    static LINK: ConsoleLink = ConsoleLink::new();
    let mut service = ConsoleService::new(
        &QUEUE,
        &LINK,
        RamStorage::<SETTINGS_BUFFER>::new(),
        DriverConfig::DEFAULT,
        Settings::DEFAULT,
        SettingsSource::Defaults,
    )
    .expect("the built-in settings are valid");
    let mut session = Session::<96, 160>::new();
    let mut line = Vec::new();
    let mut buf = [0_u8; 256];
    while !stop.load(Ordering::Relaxed) {
        // The slave stays open in the test, so a read waits for bytes.
        let Ok(n) = nix::unistd::read(master, &mut buf) else {
            return;
        };
        for &b in &buf[..n] {
            line.push(b);
            if b != b'\n' {
                continue;
            }
            if !line.windows(4).any(|w| w == b"mute") {
                session.feed(&line, &mut service, |reply| {
                    let mut rest = reply;
                    while !rest.is_empty() {
                        match nix::unistd::write(master, rest) {
                            Ok(k) => rest = &rest[k..],
                            Err(_) => return,
                        }
                    }
                });
            }
            line.clear();
        }
    }
}

/// Runs a `--port` session over a fresh pty with `input` on stdin.
fn session(input: &str) -> (bool, String) {
    let pty = openpty(None, None).expect("a pseudo-terminal pair");
    let path = std::fs::read_link(format!("/proc/self/fd/{}", pty.slave))
        .unwrap_or_else(|_| PathBuf::from("/dev/ptmx"));
    let stop = AtomicBool::new(false);
    let mut out = Vec::new();
    let ok = thread::scope(|scope| {
        scope.spawn(|| head(pty.master, &stop));
        let ok = serial_session(&path, input.as_bytes(), &mut out, Duration::from_secs(2))
            .expect("the port opens");
        stop.store(true, Ordering::Relaxed);
        // Wakes the head's read.
        let _ = nix::unistd::write(pty.slave, b"\n");
        ok
    });
    let _ = nix::unistd::close(pty.master);
    let _ = nix::unistd::close(pty.slave);
    (ok, String::from_utf8(out).expect("replies are text"))
}

#[test]
fn a_port_session_prints_one_reply_per_line_in_order() {
    let (ok, out) = session("help\nnod\nservo yaw min 2600\nfrobnicate\nservo pitch\n");
    let lines: Vec<&str> = out.lines().collect();
    assert!(ok, "every line answered: {out}");
    assert_eq!(lines.len(), 5, "{out}");
    assert!(lines[0].starts_with("ok commands: help status"), "{out}");
    assert_eq!(lines[1], "ok");
    assert!(lines[2].starts_with("err invalid "), "{out}");
    assert!(lines[3].starts_with("err "), "{out}");
    assert!(lines[4].starts_with("ok pitch neutral="), "{out}");
}

#[test]
fn a_line_without_a_reply_fails_the_session_after_the_wait() {
    let (ok, out) = session("status\nmute\nnod\n");
    assert!(!ok, "a reply was missing: {out}");
    assert_eq!(out.lines().count(), 2, "{out}");
    assert!(out.starts_with("ok mode=starting"), "{out}");
}

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
    let (vid, pid) = super::PICO_USB_ID;
    let other = usb("/dev/ttyACM0", vid, pid, Some("some other gadget"));
    let head = usb("/dev/ttyACM1", vid, pid, Some(super::PICO_PRODUCT));
    let arduino = usb("/dev/ttyACM2", 0x2341, 0x0043, Some(super::PICO_PRODUCT));
    let pty = serialport::SerialPortInfo {
        port_name: "/dev/pts/3".to_owned(),
        port_type: serialport::SerialPortType::Unknown,
    };
    let found = super::pick_pico(&[other.clone(), arduino.clone(), head, pty.clone()]);
    assert_eq!(found.unwrap(), PathBuf::from("/dev/ttyACM1"));

    // The shared ID alone is not enough when the product says otherwise.
    let err = super::pick_pico(&[other.clone(), arduino.clone(), pty]).unwrap_err();
    assert!(
        err.to_string()
            .contains("/dev/ttyACM0 (\"some other gadget\")"),
        "{err}"
    );
    let err = super::pick_pico(&[arduino]).unwrap_err();
    assert!(err.to_string().contains("is the head plugged in"), "{err}");

    // Without product strings, one device of the ID is taken; two are not.
    let bare = usb("/dev/ttyACM4", vid, pid, None);
    assert_eq!(
        super::pick_pico(&[other, bare.clone()]).unwrap(),
        PathBuf::from("/dev/ttyACM4")
    );
    let bare2 = usb("/dev/ttyACM5", vid, pid, None);
    let err = super::pick_pico(&[bare, bare2]).unwrap_err();
    assert!(
        err.to_string().contains("without a product string"),
        "{err}"
    );
}

#[test]
fn two_heads_need_a_port() {
    let (vid, pid) = super::PICO_USB_ID;
    let a = usb("/dev/ttyACM0", vid, pid, Some(super::PICO_PRODUCT));
    let b = usb("/dev/ttyACM1", vid, pid, Some(super::PICO_PRODUCT));
    let err = super::pick_pico(&[a, b]).unwrap_err();
    assert!(
        err.to_string()
            .contains("/dev/ttyACM0, /dev/ttyACM1; give --port"),
        "{err}"
    );
}
