//! The console on the board's own USB port: a CDC-ACM serial port
//! (embassy-usb), the same protocol as on the UART.
//!
//! The device is `16c0:27dd`, the VID:PID pair that Van Ooijen Technische
//! Informatica shares for CDC-ACM serial devices of hobby projects; a host
//! tells this head from other such devices by its manufacturer and product
//! strings, [`MANUFACTURER`] and [`PRODUCT`].
//!
//! Two tasks: the USB device itself ([`UsbDevice::run`], enumeration and
//! control requests) and the console over the CDC-ACM data endpoints,
//! which waits for a terminal to open the port (DTR), serves it until the
//! host goes away and then waits again, with the half-typed line forgotten.

use embassy_rp::peripherals::USB;
use embassy_rp::usb::Driver;
use embassy_usb::class::cdc_acm::{CdcAcmClass, State};
use embassy_usb::driver::EndpointError;
use embassy_usb::{Builder, Config, UsbDevice};
use static_cell::{ConstStaticCell, StaticCell};

use idle_head_firmware::console::{Gone, Port, READ_CHUNK, Received};

pub use idle_head_core::console::usb_identity::{MANUFACTURER, PID, PRODUCT, VID};

/// Full-speed bulk packets: 64 bytes.
const PACKET: u16 = 64;

/// The USB device as the driver task runs it.
pub type Device = UsbDevice<'static, Driver<'static, USB>>;
/// The CDC-ACM class as the console task uses it.
pub type Serial = CdcAcmClass<'static, Driver<'static, USB>>;

/// Configuration descriptor buffer: one CDC-ACM function with its
/// interface association is 75 bytes.
static CONFIG_DESCRIPTOR: ConstStaticCell<[u8; 96]> = ConstStaticCell::new([0; 96]);
/// BOS descriptor buffer: only the USB 2.1 header (5 bytes) and the
/// (empty) capability list.
static BOS_DESCRIPTOR: ConstStaticCell<[u8; 16]> = ConstStaticCell::new([0; 16]);
/// Control transfers: the longest request the device answers is the
/// configuration descriptor.
static CONTROL: ConstStaticCell<[u8; 96]> = ConstStaticCell::new([0; 96]);
/// The class's shared state (not `Sync`, so set up at run time).
static STATE: StaticCell<State<'static>> = StaticCell::new();

/// The device and its serial port on `driver`. Call once.
pub fn build(driver: Driver<'static, USB>) -> (Device, Serial) {
    let mut config = Config::new(VID, PID);
    config.manufacturer = Some(MANUFACTURER);
    config.product = Some(PRODUCT);
    config.serial_number = None;
    // Bus-powered; the Pico itself draws about 25 mA (servos have their
    // own supply).
    config.max_power = 100;
    config.max_packet_size_0 = 64;
    let mut builder = Builder::new(
        driver,
        config,
        CONFIG_DESCRIPTOR.take(),
        BOS_DESCRIPTOR.take(),
        &mut [],
        CONTROL.take(),
    );
    let serial = CdcAcmClass::new(&mut builder, STATE.init(State::new()), PACKET);
    (builder.build(), serial)
}

/// The CDC-ACM port as a console [`Port`]: connected while a terminal has
/// the port open.
pub struct UsbPort(pub Serial);

impl Port for UsbPort {
    async fn connected(&mut self) {
        self.0.wait_connection().await;
    }

    fn open(&self) -> bool {
        self.0.dtr()
    }

    async fn read(&mut self, buf: &mut [u8]) -> Result<Received, Gone> {
        // `serve` reads into a whole packet (`READ_CHUNK`). USB has flow
        // control: the host holds what the device is not ready for, so
        // nothing is lost here.
        let n = self.0.read_packet(buf).await.map_err(gone)?;
        Ok(Received::Bytes(n))
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Gone> {
        for chunk in bytes.chunks(usize::from(PACKET)) {
            self.0.write_packet(chunk).await.map_err(gone)?;
        }
        // A transfer that ends on a full packet needs a zero-length packet
        // to end it, or the host waits for more.
        if bytes.len().is_multiple_of(usize::from(PACKET)) {
            self.0.write_packet(&[]).await.map_err(gone)?;
        }
        Ok(())
    }
}

fn gone(_: EndpointError) -> Gone {
    Gone
}

const _: () = assert!(
    READ_CHUNK >= PACKET as usize,
    "a read must hold a whole packet"
);
