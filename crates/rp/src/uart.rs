//! The console on a UART: 115200 8N1, 3.3 V levels, on embassy-rp's
//! buffered UART driver.

use embassy_rp::Peri;
use embassy_rp::interrupt::typelevel::{Binding, Interrupt};
use embassy_rp::uart::{self, BufferedInterruptHandler, BufferedUart, RxPin, TxPin};
use idle_head_firmware::console::{Gone, Port, Received, UART_BAUD};
use static_cell::ConstStaticCell;

use crate::PORT_PRIORITY;

/// The UART console's buffers: the console task waits while a reply
/// drains from the transmit buffer; the receive buffer holds what arrives
/// while the loop generator keeps thread mode busy (about 2 ms, 23 bytes
/// at 115200 baud).
static UART_TX: ConstStaticCell<[u8; 64]> = ConstStaticCell::new([0; 64]);
static UART_RX: ConstStaticCell<[u8; 64]> = ConstStaticCell::new([0; 64]);

/// The console's UART on `uart`, its `tx` and `rx` pins, at [`UART_BAUD`];
/// its interrupt below the frame task's. Call once: it takes the buffers.
pub fn console<T: uart::Instance>(
    uart: Peri<'static, T>,
    tx: Peri<'static, impl TxPin<T>>,
    rx: Peri<'static, impl RxPin<T>>,
    irqs: impl Binding<T::Interrupt, BufferedInterruptHandler<T>>,
) -> UartPort {
    let mut config = uart::Config::default();
    config.baudrate = UART_BAUD;
    let uart = BufferedUart::new(uart, tx, rx, irqs, UART_TX.take(), UART_RX.take(), config);
    T::Interrupt::set_priority(PORT_PRIORITY);
    UartPort(uart)
}

/// A UART as a console [`Port`]: always there.
pub struct UartPort(BufferedUart);

impl Port for UartPort {
    async fn read(&mut self, buf: &mut [u8]) -> Result<Received, Gone> {
        match embedded_io_async::Read::read(&mut self.0, buf).await {
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
        embedded_io_async::Write::write_all(&mut self.0, bytes)
            .await
            .map_err(|_| Gone)
    }
}
