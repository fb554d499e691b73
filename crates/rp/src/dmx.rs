//! The DMX512 receiver on UART1: 250 kbaud, 8N2, receive only, behind an
//! RS-485 transceiver (a MAX485 or similar with its driver disabled; see
//! the book's show control chapter for the wiring).
//!
//! # Breaks
//!
//! A DMX frame starts with a break: the line held low for at least 88 µs,
//! longer than a character. The RP2040's UART (an Arm PL011) detects it
//! itself and puts one zero character with its break flag into the receive
//! FIFO, in order with the bytes around it; a framing, parity or overrun
//! error is flagged on its character the same way. So the receiver is the
//! UART's receive interrupt reading the FIFO character by character into
//! the firmware layer's [`RECEIVER`] (the core's decoder, which keeps only
//! the personality's slots): no task, no DMA, no frame buffer. The
//! interrupt comes at 8 characters and at a pause of 32 bit periods, at the
//! highest priority (with the time driver's alarm): its FIFO holds 32
//! characters, 1.4 ms of DMX, and the frame task runs longer than that
//! once a loop (its status line, which scans the stack for its peak), so
//! below it a frame would be lost every 30 s. Reading a few characters
//! takes microseconds: the frames' timing does not see it.
//!
//! embassy-rp's `UartRx::read_to_break` would find breaks too, with DMA
//! into a buffer and a task to wake; the interrupt does the same work with
//! a fraction of its flash and RAM, which the firmware's budgets ask for.
//! (PIO is not needed: the UART already finds breaks.)

use embassy_rp::Peri;
use embassy_rp::interrupt::{self, InterruptExt, Priority};
use embassy_rp::pac;
use embassy_rp::peripherals::UART1;
use embassy_rp::uart::{self, Blocking, DataBits, Parity, RxPin, StopBits, UartRx};
use idle_head_firmware::boot::{LINKS, RECEIVER};
use idle_head_firmware::dmx::Rx;

/// DMX512's line rate.
pub const BAUD: u32 = 250_000;

/// UART1 set up for DMX on `rx` (its interrupt not yet on: [`listen`]).
#[must_use]
pub fn receiver(uart: Peri<'static, UART1>, rx: Peri<'static, impl RxPin<UART1>>) -> DmxUart {
    let mut config = uart::Config::default();
    config.baudrate = BAUD;
    config.data_bits = DataBits::DataBits8;
    config.stop_bits = StopBits::STOP2;
    config.parity = Parity::ParityNone;
    DmxUart(UartRx::new_blocking(uart, rx, config))
}

/// UART1, configured for DMX.
pub struct DmxUart(UartRx<'static, Blocking>);

/// Starts receiving: from now on UART1's interrupt reads its FIFO.
pub fn listen(uart: DmxUart) {
    // The interrupt handler owns the UART from now on.
    let DmxUart(rx) = uart;
    core::mem::forget(rx);
    let regs = pac::UART1;
    // Interrupt at 8 characters (1/4 full) and at a pause.
    regs.uartifls().write(|w| w.set_rxiflsel(0b001));
    regs.uartimsc().write(|w| {
        w.set_rxim(true);
        w.set_rtim(true);
    });
    interrupt::UART1_IRQ.set_priority(Priority::P0);
    interrupt::UART1_IRQ.unpend();
    // Note(unsafe): the handler below takes nothing that a critical
    // section does not guard.
    unsafe { interrupt::UART1_IRQ.enable() };
}

#[embassy_rp::interrupt]
unsafe fn UART1_IRQ() {
    let regs = pac::UART1;
    RECEIVER.lock(|cell| {
        let Ok(mut receiver) = cell.try_borrow_mut() else {
            return;
        };
        while !regs.uartfr().read().rxfe() {
            let dr = regs.uartdr().read();
            let rx = if dr.be() {
                Rx::Break
            } else if dr.fe() || dr.pe() || dr.oe() {
                Rx::Error
            } else {
                Rx::Byte(dr.data())
            };
            receiver.take(rx, &LINKS.show.dmx);
        }
        receiver.flush();
    });
    // Reading the FIFO clears the receive interrupts but the timeout's.
    regs.uarticr().write(|w| w.set_rtic(true));
}
