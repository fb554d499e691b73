//! The LM3S6965's UART0 (the console) and UART1 (the host's hang-up line),
//! as QEMU models them (a PL011 with the Stellaris identification):
//! interrupt-driven receive, polled transmit.
//!
//! QEMU connects UART0 to its first `-serial` and UART1 to its second. The
//! receive interrupt only wakes the console task: the handler masks it and
//! signals, the task empties the receive register and unmasks it again.
//! Bytes the task has not read yet stay in QEMU's character device (which
//! stops reading its socket while the register is full): nothing is
//! dropped, and the frame task, in a higher-priority interrupt, never
//! waits for the console. The FIFOs stay off: QEMU empties them when they
//! are turned on, and the host, which QEMU waits for before it starts the
//! machine, may have sent its first byte by then.

use core::ptr;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;

/// Register offsets (Stellaris LM3S6965 data sheet, table 12-3).
const DR: usize = 0x000;
const FR: usize = 0x018;
const LCRH: usize = 0x02c;
const CTL: usize = 0x030;
const IM: usize = 0x038;
const ICR: usize = 0x044;

/// FR: nothing received, transmit full (FIFO or holding register).
const FR_RXFE: u32 = 1 << 4;
const FR_TXFF: u32 = 1 << 5;
/// LCRH: 8 data bits (8N1), FIFOs off (one-byte holding registers).
const LCRH_8N1: u32 = 0b11 << 5;
/// CTL: UART, transmitter and receiver on.
const CTL_ON: u32 = 1 | 1 << 8 | 1 << 9;
/// IM / ICR: the receive interrupt.
const RX_INT: u32 = 1 << 4;

/// Set when a receive interrupt fired; the console task waits on it.
pub static RX_READY: Signal<CriticalSectionRawMutex, ()> = Signal::new();

/// One of the UARTs.
#[derive(Clone, Copy)]
pub struct Uart {
    base: usize,
}

/// UART0, the console: interrupt 5.
pub const UART0: Uart = Uart { base: 0x4000_c000 };
/// UART1, the host's hang-up line: interrupt 6.
pub const UART1: Uart = Uart { base: 0x4000_d000 };
/// Their interrupt numbers.
pub const UART0_IRQ: u16 = 5;
pub const UART1_IRQ: u16 = 6;

impl Uart {
    fn read_reg(self, offset: usize) -> u32 {
        // Note(unsafe): an aligned register of a UART that exists on this
        // machine; reads have no side effect but on DR, which is read only
        // by the console task.
        unsafe { ptr::read_volatile((self.base + offset) as *const u32) }
    }

    fn write_reg(self, offset: usize, value: u32) {
        // Note(unsafe): as `read_reg`; the UART is owned by the console
        // task, the interrupt handler only masks the interrupt.
        unsafe { ptr::write_volatile((self.base + offset) as *mut u32, value) }
    }

    /// 8N1, receive interrupt on. (QEMU ignores the baud
    /// rate; a board would set IBRD and FBRD for 115200 here.)
    pub fn init(self) {
        self.write_reg(CTL, 0);
        self.write_reg(LCRH, LCRH_8N1);
        self.write_reg(ICR, 0x7ff);
        self.write_reg(CTL, CTL_ON);
        self.listen();
    }

    /// Whether a received byte waits (none is taken).
    pub fn pending(self) -> bool {
        self.read_reg(FR) & FR_RXFE == 0
    }

    /// The next received byte, if any. A received BREAK reads as a NUL.
    pub fn read(self) -> Option<u8> {
        if self.pending() {
            Some((self.read_reg(DR) & 0xff) as u8)
        } else {
            None
        }
    }

    /// Sends `bytes`, waiting while the transmitter is full.
    pub fn write_all(self, bytes: &[u8]) {
        for &b in bytes {
            while self.read_reg(FR) & FR_TXFF != 0 {}
            self.write_reg(DR, u32::from(b));
        }
    }

    /// Unmasks the receive interrupt (it fires at once if bytes wait).
    pub fn listen(self) {
        self.write_reg(IM, RX_INT);
    }

    /// From the interrupt handler: masks the receive interrupt and wakes
    /// the console task.
    pub fn on_interrupt(self) {
        self.write_reg(IM, 0);
        RX_READY.signal(());
    }
}
