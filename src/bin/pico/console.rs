//! The console on the Pico's two ports: UART0 (GP0 TX, GP1 RX, 115200 8N1)
//! and the board's USB port (CDC-ACM, `usb.rs`).
//!
//! Each port has a task of its own in thread mode with its own
//! [`Session`]: bytes in, one reply line out per input line. The commands
//! are carried out by a [`Handler`], the one generic parameter of
//! [`serve`]; actions reach the frame task only through its
//! [`CommandQueue`], which it drains between frames. The frame task runs in
//! the interrupt executor above both console tasks, and the ports'
//! interrupts sit below it ([`PORT_PRIORITY`]): a flood of bytes on either
//! port never delays a frame.
//!
//! The handler for now, [`QueueHandler`] (`handler.rs`), answers `help`, queues the motion
//! commands (`nod`, `look`, `stop`, ...; a full queue is `err busy`) and
//! answers every other command `err state not available yet`: status,
//! servo calibration and saved settings need the settings service, which
//! takes its place.

use embassy_rp::interrupt::Priority;
use embassy_rp::uart::BufferedUart;
use idle_head::console::{Handler, Session};

pub use crate::handler::{PicoSession, Queue, QueueHandler};

/// The ports' interrupt priority: below the frame task's (`P1`), above
/// thread mode, where the console tasks run.
pub const PORT_PRIORITY: Priority = Priority::P2;

/// The UART's baud rate (8 data bits, no parity, 1 stop bit).
pub const UART_BAUD: u32 = 115_200;

/// Bytes [`serve`] reads at once: a full-speed USB packet.
pub const READ_CHUNK: usize = 64;

/// A byte port the console runs over.
pub trait Port {
    /// Waits for bytes and reads some into `buf`; `Err` when the port is
    /// gone (a USB host disconnected).
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Gone>;
    /// Writes all of `bytes`.
    async fn write(&mut self, bytes: &[u8]) -> Result<(), Gone>;
}

/// The port went away: the session ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub struct Gone;

/// Runs `session` over `port` until the port goes away: every line gets
/// exactly one reply from `handler`.
pub async fn serve<P: Port, H: Handler, const LINE: usize, const REPLY: usize>(
    port: &mut P,
    session: &mut Session<LINE, REPLY>,
    handler: &mut H,
) -> Gone {
    let mut buf = [0; READ_CHUNK];
    loop {
        let n = match port.read(&mut buf).await {
            Ok(n) => n,
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

impl Port for BufferedUart {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Gone> {
        loop {
            match embedded_io_async::Read::read(self, buf).await {
                Ok(n) => return Ok(n),
                // A framing, parity, break or overrun error: the bytes
                // around it are lost, so the line in progress fails the
                // framer or the parser and gets its `err` reply. The
                // UART itself keeps working.
                Err(e) => defmt::warn!("console uart: {}", e),
            }
        }
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Gone> {
        // The buffered UART's writes never fail.
        embedded_io_async::Write::write_all(self, bytes)
            .await
            .map_err(|_| Gone)
    }
}
