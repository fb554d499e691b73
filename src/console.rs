//! The console on the Pico's two ports: UART0 (GP0 TX, GP1 RX, 115200 8N1)
//! and the board's USB port (CDC-ACM, `usb.rs`).
//!
//! Each port has a task of its own in thread mode with its own
//! [`Session`]: bytes in, one reply line out per input line. The commands
//! are carried out by a [`Handler`], the one generic parameter of
//! [`serve`]; actions reach the frame task only through its
//! [`CommandQueue`], which it drains between frames, and servo
//! calibrations, seeds and the head's status through the
//! [`ConsoleLink`](idle_head_core::console::ConsoleLink). The frame task runs in
//! the interrupt executor above both console tasks, and the ports'
//! interrupts sit below it ([`PORT_PRIORITY`]): a flood of bytes on either
//! port never delays a frame.
//!
//! The handler is the core's `ConsoleService`, one for both ports
//! ([`Shared`], `handler.rs`), with the settings store in flash
//! (`settings.rs`): a servo changed on one port shows on the other.
//!
//! [`CommandQueue`]: idle_head_core::behaviour::CommandQueue

use embassy_executor::Spawner;
use embassy_rp::Peri;
use embassy_rp::interrupt::{self, InterruptExt, Priority};
use embassy_rp::peripherals::{PIN_0, PIN_1, UART0, USB};
use embassy_rp::uart::{self, BufferedInterruptHandler, BufferedUart};
use idle_head_core::console::{Handler, Session};
use static_cell::ConstStaticCell;

use crate::settings::PicoStorage;
use crate::usb;
use idle_head_core::console::{PortSession, Shared, SharedService};

/// The service both ports share.
pub type Service = SharedService<PicoStorage>;

/// The ports' interrupt priority: below the frame task's (`P1`), above
/// thread mode, where the console tasks run.
pub const PORT_PRIORITY: Priority = Priority::P2;

/// The UART's baud rate (8 data bits, no parity, 1 stop bit).
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
pub trait Port {
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
/// (docs/protocol.md says what a flood does to the lines around it).
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

impl Port for BufferedUart {
    async fn read(&mut self, buf: &mut [u8]) -> Result<Received, Gone> {
        match embedded_io_async::Read::read(self, buf).await {
            Ok(n) => Ok(Received::Bytes(n)),
            // A framing, parity, break or overrun error: bytes around it
            // are lost, and the line they belonged to gets an `err` reply
            // saying so. The UART itself keeps working.
            Err(e) => {
                defmt::warn!("console uart: {}: received bytes lost", e);
                Ok(Received::Lost)
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

/// The UART console's buffers: the console task waits while a reply
/// drains from the transmit buffer; the receive buffer holds what arrives
/// while the loop generator keeps thread mode busy (about 2 ms, 23 bytes
/// at 115200 baud).
static UART_TX: ConstStaticCell<[u8; 64]> = ConstStaticCell::new([0; 64]);
static UART_RX: ConstStaticCell<[u8; 64]> = ConstStaticCell::new([0; 64]);

embassy_rp::bind_interrupts!(struct Irqs {
    UART0_IRQ => BufferedInterruptHandler<UART0>;
    USBCTRL_IRQ => embassy_rp::usb::InterruptHandler<USB>;
});

/// The peripherals the console takes: UART0 on GP0 (TX) and GP1 (RX), and
/// the USB controller.
pub struct Ports {
    pub uart: Peri<'static, UART0>,
    pub tx: Peri<'static, PIN_0>,
    pub rx: Peri<'static, PIN_1>,
    pub usb: Peri<'static, USB>,
}

/// Starts the console on both ports, in thread mode (`spawner`), handing
/// commands to `service`. Call once.
pub fn start(spawner: Spawner, ports: Ports, service: &'static Service) {
    let mut uart_config = uart::Config::default();
    uart_config.baudrate = UART_BAUD;
    let uart = BufferedUart::new(
        ports.uart,
        ports.tx,
        ports.rx,
        Irqs,
        UART_TX.take(),
        UART_RX.take(),
        uart_config,
    );
    interrupt::UART0_IRQ.set_priority(PORT_PRIORITY);
    match uart_console(uart, service) {
        Ok(token) => {
            spawner.spawn(token);
            defmt::info!("console: UART0 GP0 TX, GP1 RX, {=u32} 8N1", UART_BAUD);
        }
        Err(_) => defmt::error!("uart console task already running"),
    }

    let (device, serial) = usb::build(embassy_rp::usb::Driver::new(ports.usb, Irqs));
    interrupt::USBCTRL_IRQ.set_priority(PORT_PRIORITY);
    match (usb_device(device), usb_console(serial, service)) {
        (Ok(device), Ok(console)) => {
            spawner.spawn(device);
            spawner.spawn(console);
            defmt::info!(
                "console: USB CDC-ACM {=u16:04x}:{=u16:04x}",
                usb::VID,
                usb::PID
            );
        }
        _ => defmt::error!("usb tasks already running"),
    }
}

/// The USB device: enumeration, control requests, bus resets.
#[embassy_executor::task]
async fn usb_device(mut device: usb::Device) {
    device.run().await
}

/// The console on the USB serial port: one session per connection.
#[embassy_executor::task]
async fn usb_console(mut serial: usb::Serial, service: &'static Service) {
    let mut session = PortSession::new();
    let mut handler = Shared::new(service);
    loop {
        serial.wait_connection().await;
        session.reset();
        let mut port = usb::UsbPort {
            serial: &mut serial,
        };
        serve(&mut port, &mut session, &mut handler).await;
    }
}

/// The console on UART0, for as long as the board runs.
#[embassy_executor::task]
async fn uart_console(mut uart: BufferedUart, service: &'static Service) {
    let mut session = PortSession::new();
    let mut handler = Shared::new(service);
    // A UART never goes away: `serve` only returns if it did.
    let gone = serve(&mut uart, &mut session, &mut handler).await;
    defmt::error!("console uart ended: {}", gone);
}
