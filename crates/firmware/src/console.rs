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
//! A board implements [`Port`] for each of its transports and runs
//! [`run`] in a task per port.
//!
//! [`CommandQueue`]: idle_head_core::behaviour::CommandQueue

use idle_head_core::console::{Handler, PortSession, Session, Shared, SharedService};
use idle_head_core::settings::SettingsStorage;

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

/// Runs the console on `port` for as long as the board runs: a session per
/// connection (the half-typed line of a host that went away is forgotten),
/// commands carried out by the shared `service`.
pub async fn run<P: Port, S: SettingsStorage>(
    port: &mut P,
    service: &'static SharedService<S>,
    name: &'static str,
) -> ! {
    let mut session = PortSession::new();
    let mut handler = Shared::new(service);
    loop {
        port.connected().await;
        session.reset();
        let Gone = serve(port, &mut session, &mut handler).await;
        defmt::info!("console {=str}: the host went away", name);
    }
}
