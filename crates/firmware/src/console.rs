//! The console on a board's byte ports (a UART, a USB serial port).
//!
//! Each port has a task of its own in thread mode with its own
//! [`Session`]: bytes in, one reply line out per input line. The commands
//! are carried out by a [`Handler`], the one generic parameter of
//! [`serve`]; actions reach the frame task only through its
//! [`CommandQueue`], which it drains between frames, and servo
//! calibrations, seeds and the head's status through the
//! [`ConsoleLink`](idle_head_core::console::ConsoleLink). The frame task runs
//! in an executor above the console tasks, and the ports' interrupts sit
//! below it: a flood of bytes on any port never delays a frame.
//!
//! The handler is the core's `ConsoleService`, one for all ports
//! ([`Shared`]), with the board's settings store: a servo changed on one
//! port shows on the other.
//!
//! A port becomes a Bottango driver at a valid Bottango handshake
//! ([`DualSession`]), until Bottango's `STOP` or until the port goes
//! away: its curves go to the frame task through the show link
//! ([`SHOW`](crate::boot::SHOW)). In a Bottango session a line that stops
//! arriving for 50 ms is dropped and answered `TIMEOUT`, as Bottango's own
//! driver does.
//!
//! A board implements [`Port`] for each of its transports and runs
//! [`run`] in a task per port.
//!
//! [`CommandQueue`]: idle_head_core::behaviour::CommandQueue

use embassy_time::{Duration, with_timeout};
use idle_head_core::bottango::TIMEOUT_MS;
use idle_head_core::console::{DualSession, Handler, Session, Shared, SharedService};
use idle_head_core::settings::SettingsStorage;

use crate::boot::SHOW;

/// The console's baud rate on a UART (8 data bits, no parity, 1 stop bit).
pub const UART_BAUD: u32 = 115_200;

/// Bytes [`serve`] reads at once: a full-speed USB packet.
pub const READ_CHUNK: usize = 64;

/// What a [`Port`] read brought.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Received {
    /// This many bytes, in the buffer.
    Bytes(usize),
    /// Received bytes were lost (a UART overrun or framing error).
    Lost,
}

/// A byte port the console runs over.
// The executors here are single-threaded: no `Send` bound is wanted on the
// futures, which is what the lint warns about.
#[allow(async_fn_in_trait)]
pub trait Port {
    /// Waits until a host is there to talk to (a terminal opened a USB
    /// serial port); at once for a port that is always there (a UART).
    async fn connected(&mut self) {}
    /// Waits for bytes and reads some into `buf`, or reports received
    /// bytes lost; `Err` when the port is gone (a USB host disconnected).
    async fn read(&mut self, buf: &mut [u8]) -> Result<Received, Gone>;
    /// Writes all of `bytes`.
    async fn write(&mut self, bytes: &[u8]) -> Result<(), Gone>;
}

/// The port went away: the session ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub struct Gone;

/// Runs `session` over `port` until the port goes away: every line gets
/// exactly one reply from `handler`. When the port reports received bytes
/// lost, the line in progress is answered `err line bytes lost …`
/// (docs/user/protocol.md says what a flood does to the lines around it).
pub async fn serve<P: Port, H: Handler, const LINE: usize, const REPLY: usize>(
    port: &mut P,
    session: &mut Session<LINE, REPLY>,
    handler: &mut H,
) -> Gone {
    let mut buf = [0; READ_CHUNK];
    loop {
        let n = match port.read(&mut buf).await {
            Ok(Received::Bytes(n)) => n,
            Ok(Received::Lost) => {
                session.lose();
                continue;
            }
            Err(gone) => return gone,
        };
        for &byte in buf.get(..n).unwrap_or_default() {
            if let Some(reply) = session.push(byte, handler)
                && let Err(gone) = port.write(reply).await
            {
                return gone;
            }
        }
    }
}

/// Runs `session` over `port` until the port goes away, as [`serve`] does;
/// in a Bottango session a line that pauses for [`TIMEOUT_MS`] is dropped
/// and answered `TIMEOUT`.
pub async fn serve_dual<P: Port, H: Handler>(
    port: &mut P,
    session: &mut DualSession<'_>,
    handler: &mut H,
) -> Gone {
    let mut buf = [0; READ_CHUNK];
    loop {
        // One read call and one write call (one future each in flash), the
        // read with a timeout that only matters in a Bottango session with
        // a line in progress.
        let armed = session.bottango() && session.in_progress();
        let wait = if armed { TIMEOUT_MS } else { IDLE_WAIT_MS };
        let (n, mut timed_out) =
            match with_timeout(Duration::from_millis(wait), port.read(&mut buf)).await {
                Ok(Ok(Received::Bytes(n))) => (n, false),
                Ok(Ok(Received::Lost)) => {
                    session.lose();
                    continue;
                }
                Ok(Err(gone)) => return gone,
                Err(_) => (0, true),
            };
        let was = session.bottango();
        let mut bytes = buf.get(..n).unwrap_or_default().iter();
        loop {
            let reply = if core::mem::take(&mut timed_out) {
                session.timeout()
            } else if let Some(&byte) = bytes.next() {
                session.push(byte, handler)
            } else {
                break;
            };
            if let Some(reply) = reply
                && !reply.is_empty()
                && let Err(gone) = port.write(reply).await
            {
                return gone;
            }
        }
        log_mode(was, session.bottango());
    }
}

/// How long a read waits before looking again when no timeout is due.
const IDLE_WAIT_MS: u64 = 60_000;

/// Logs a port switching to Bottango's protocol or back.
fn log_mode(was: bool, is: bool) {
    match (was, is) {
        (false, true) => defmt::info!(
            "console: Bottango handshake: a Bottango driver (protocol {=str}) until STOP",
            idle_head_core::bottango::VERSION
        ),
        (true, false) => defmt::info!("console: Bottango STOP: the console again"),
        _ => {}
    }
}

/// Runs the console on `port` for as long as the board runs: a session per
/// connection (the half-typed line of a host that went away is forgotten,
/// a Bottango session ends), commands carried out by the shared `service`.
pub async fn run<P: Port, S: SettingsStorage>(
    port: &mut P,
    service: &'static SharedService<S>,
    name: &'static str,
) -> ! {
    let mut session = DualSession::new(Some(&SHOW.curves));
    let mut handler = Shared::new(service);
    loop {
        port.connected().await;
        session.reset();
        let Gone = serve_dual(port, &mut session, &mut handler).await;
        session.reset();
        defmt::info!("console {=str}: the host went away", name);
    }
}
