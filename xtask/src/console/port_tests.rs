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
use idle_head_core::console::{ConsoleLink, ConsoleService, Session, outcome_reply};
use idle_head_core::driver::DriverConfig;
use idle_head_core::settings::{RamStorage, SETTINGS_BUFFER, Settings, SettingsSource};
use nix::pty::openpty;

use super::serial_session;
use super::talk::Talk;

/// A head on the master side of a pty: every line in, the firmware's
/// replies out, until `stop`. Lines containing `mute` get no reply, so
/// that the session's count of missing replies can be checked; at a line
/// containing `unplug`, the head goes away: it closes the pty's master.
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
    let behaviour = Settings::DEFAULT
        .validate(&DriverConfig::DEFAULT)
        .expect("the built-in settings are valid")
        .behaviour;
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
            if line.windows(6).any(|w| w == b"unplug") {
                // The replies already written are read first (a hang-up
                // discards what the other side has not read yet).
                thread::sleep(Duration::from_millis(300));
                let _ = nix::unistd::close(master);
                return;
            }
            if !line.windows(4).any(|w| w == b"mute") {
                let write = |reply: &[u8]| {
                    let mut rest = reply;
                    while !rest.is_empty() {
                        match nix::unistd::write(master, rest) {
                            Ok(k) => rest = &rest[k..],
                            Err(_) => return,
                        }
                    }
                };
                for &byte in &line {
                    if let Some(reply) = session.push(byte, &mut service) {
                        write(reply);
                    }
                    // A queued action: the frame task's answer, as the
                    // mixer of a head at rest gives it.
                    if session.waiting().is_some()
                        && let Some((action, _)) = QUEUE.take_asked()
                    {
                        let outcome = behaviour.check(&action);
                        if let Some(reply) = session.finish(|r| outcome_reply(r, &outcome)) {
                            write(reply);
                        }
                    }
                }
            }
            line.clear();
        }
    }
}

/// What a `--port` session printed and how it went.
struct Outcome {
    /// The reply lines, as bytes.
    replies: Vec<Vec<u8>>,
    /// The session's own account.
    talk: Talk,
}

impl Outcome {
    fn text(&self) -> String {
        self.replies
            .iter()
            .map(|r| String::from_utf8_lossy(r) + "\n")
            .collect()
    }
}

/// Runs a `--port` session over a fresh pty with `input` on stdin.
fn session(input: &[u8]) -> Outcome {
    let pty = openpty(None, None).expect("a pseudo-terminal pair");
    let path = std::fs::read_link(format!("/proc/self/fd/{}", pty.slave))
        .unwrap_or_else(|_| PathBuf::from("/dev/ptmx"));
    let stop = AtomicBool::new(false);
    let unplugs = input.windows(6).any(|w| w == b"unplug");
    let mut replies = Vec::new();
    let talk = thread::scope(|scope| {
        let head = scope.spawn(|| head(pty.master, &stop));
        let talk = serial_session(
            &path,
            input,
            |reply: &[u8]| replies.push(reply.to_vec()),
            Duration::from_secs(2),
        )
        .expect("the port opens");
        stop.store(true, Ordering::Relaxed);
        if !unplugs {
            // Wakes the head's read.
            let _ = nix::unistd::write(pty.slave, b"\n");
        }
        let _ = head.join();
        talk
    });
    // The head closed the master itself when it was unplugged.
    if !unplugs {
        let _ = nix::unistd::close(pty.master);
    }
    let _ = nix::unistd::close(pty.slave);
    Outcome { replies, talk }
}

#[test]
fn a_port_session_prints_one_reply_per_line_in_order() {
    let outcome = session(b"help\nnod\nservo yaw min 2600\nfrobnicate\nservo pitch\n");
    let out = outcome.text();
    let lines: Vec<&str> = out.lines().collect();
    assert!(
        outcome.talk.problems().is_empty(),
        "every line answered: {out}"
    );
    assert_eq!(lines.len(), 5, "{out}");
    assert!(lines[0].starts_with("ok commands: help status"), "{out}");
    assert!(lines[1].starts_with("ok nod amp_mdeg="), "{out}");
    assert!(lines[2].starts_with("err invalid "), "{out}");
    assert!(lines[3].starts_with("err "), "{out}");
    assert!(lines[4].starts_with("ok pitch neutral="), "{out}");
}

#[test]
fn a_line_that_is_not_utf8_reaches_the_head_and_the_next_lines_too() {
    // CR, LF and CR LF each end one line, as on the head; the last line's
    // missing line end is added.
    let outcome = session(b"help\nnod \xff\r\nnod \xc3\xa9\rstatus");
    let out = outcome.text();
    assert!(outcome.talk.problems().is_empty(), "{out}");
    assert_eq!(outcome.talk.sent, 4);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 4, "{out}");
    assert!(lines[0].starts_with("ok commands:"), "{out}");
    assert_eq!(lines[1], "err line not UTF-8 from byte 4 on", "{out}");
    // The head quotes a word that is not ASCII as escapes: it did get é.
    assert!(lines[2].starts_with("err syntax `\\xc3\\xa9`"), "{out}");
    assert!(lines[3].starts_with("ok mode="), "{out}");
}

#[test]
fn a_line_without_a_reply_fails_the_session_after_the_wait() {
    let outcome = session(b"status\nmute\nnod\n");
    let out = outcome.text();
    assert_eq!(
        outcome.talk.problems(),
        ["1 of 3 lines got no reply"],
        "{out}"
    );
    assert_eq!(out.lines().count(), 2, "{out}");
    assert!(out.starts_with("ok mode=starting"), "{out}");
}

#[test]
fn a_port_that_goes_away_ends_the_session_with_a_reason() {
    let outcome = session(b"status\nunplug\nstatus\nhelp\n");
    assert_eq!(outcome.replies.len(), 1, "{}", outcome.text());
    let early = outcome.talk.early.as_deref().unwrap_or_default();
    assert!(
        early.starts_with("reading the port failed")
            || early.starts_with("writing to the port failed")
            || early == "the port closed",
        "{early:?}"
    );
    assert_eq!(outcome.talk.missing(), 3);
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
