//! The console on UART0: 115200 8N1, 3.3 V levels.
//!
//! Received characters go by DMA into a ring in RAM, [`RX_CHARS`] long. A
//! timer alarm of its own looks at the DMA's count every [`POLL`] and wakes
//! the console task when characters came (a few dozen instructions a
//! millisecond, where a task woken by an embassy timer would cost over a
//! thousand). The UART's own 32-byte
//! FIFO would overflow 2.8 ms after the CPU stopped reading it, and a `save`
//! holds the interrupts off while a flash sector is erased (45 ms typically,
//! 400 ms at worst): the DMA needs neither the CPU nor the flash, and the
//! ring holds 0.35 s of continuous input. The DMA moves the data register's
//! 16 bits, so each character keeps its framing, parity, break and overrun
//! flags: a damaged character is known exactly, and so is the line it
//! belongs to. Should the ring ever be lapped, the port reports the lost
//! bytes (the line in progress is answered `err line bytes lost`).
//!
//! Bytes to send go straight into the transmit FIFO while it has room and
//! nothing waits before them; the rest wait in a buffer of [`TX_BYTES`],
//! from which UART0's interrupt fills the FIFO: a reply is handed over at
//! once, and the console goes on reading while it goes out.

use core::cell::{RefCell, UnsafeCell};
use core::ptr;
use core::sync::atomic::{AtomicU8, AtomicU32, Ordering};

use embassy_rp::Peri;
use embassy_rp::dma::ChannelInstance;
use embassy_rp::interrupt::{self, InterruptExt};
use embassy_rp::pac;
use embassy_rp::pac::dma::vals::{DataSize, TreqSel};
use embassy_rp::peripherals::UART0;
use embassy_rp::uart::{self, Blocking, RxPin, TxPin, Uart};
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::Duration;
use heapless::Deque;
use idle_head_firmware::console::{Gone, Port, Received, UART_BAUD};

use crate::PORT_PRIORITY;

/// Characters the receive ring holds: 4096 · 86.8 µs = 0.36 s at 115200 8N1.
pub const RX_CHARS: usize = 4096;
/// Bytes waiting to be sent: a few replies.
pub const TX_BYTES: usize = 512;
/// How often the alarm looks at the receive ring: what a byte waits at
/// most before the console sees it.
pub const POLL: Duration = Duration::from_millis(1);

/// The timer alarm that looks at the ring (embassy-time's driver uses 0).
const ALARM: usize = 1;

/// The receive DMA channel, for the alarm.
static CHANNEL: AtomicU8 = AtomicU8::new(0);
/// The DMA's transfer count when the alarm last looked.
static LOOKED: AtomicU32 = AtomicU32::new(START);
/// Signalled by the alarm when characters came (or the DMA's count ran out).
static RX_CAME: Signal<CriticalSectionRawMutex, ()> = Signal::new();

/// The ring's size as the DMA counts it: 2^13 bytes of 16-bit characters.
const RING_BITS: u8 = 13;
const _: () = assert!(1 << RING_BITS == RX_CHARS * 2);

/// The characters the DMA writes, aligned to their size (the DMA's ring
/// wraps its write address on that boundary).
#[repr(C, align(8192))]
struct RxRing(UnsafeCell<[u16; RX_CHARS]>);

// Note(unsafe): only the DMA writes the ring, and only the one console task
// on this UART reads it, with volatile reads of whole characters.
unsafe impl Sync for RxRing {}

static RX_RING: RxRing = RxRing(UnsafeCell::new([0; RX_CHARS]));

/// The bytes to send, shared with UART0's interrupt.
static TX: Mutex<CriticalSectionRawMutex, RefCell<Deque<u8, TX_BYTES>>> =
    Mutex::new(RefCell::new(Deque::new()));
/// Signalled by the interrupt when it has made room in [`TX`].
static TX_ROOM: Signal<CriticalSectionRawMutex, ()> = Signal::new();

/// The DMA's transfer count at the start: it counts down one a character.
/// (The RP2350's count field is 28 bits wide.)
#[cfg(feature = "rp2040")]
const START: u32 = 0x7fff_ffff;
#[cfg(feature = "rp235xa")]
const START: u32 = 0x0fff_ffff;

/// The error flags of a character in the data register: overrun, break,
/// parity, framing.
const ERRORS: u16 = 0xf00;

/// The console's UART0 on its `tx` and `rx` pins at [`UART_BAUD`],
/// receiving through DMA channel `dma`; its interrupt at the ports'
/// priority. Call once.
pub fn console<D: ChannelInstance>(
    uart: Peri<'static, UART0>,
    tx: Peri<'static, impl TxPin<UART0>>,
    rx: Peri<'static, impl RxPin<UART0>>,
    // The channel is this port's from now on: its registers are set below.
    _dma: Peri<'static, D>,
) -> UartPort {
    let mut config = uart::Config::default();
    config.baudrate = UART_BAUD;
    // Pins, line rate and format; the port takes over the registers.
    let _: Uart<'static, Blocking> = Uart::new_blocking(uart, tx, rx, config);
    let channel = D::number();
    CHANNEL.store(channel, Ordering::Relaxed);
    let regs = pac::UART0;
    let ch = pac::DMA.ch(usize::from(channel));
    ch.read_addr().write_value(regs.uartdr().as_ptr() as u32);
    ch.write_addr().write_value(RX_RING.0.get() as u32);
    set_count(ch);
    ch.ctrl_trig().write(|w| {
        w.set_data_size(DataSize::SIZE_HALFWORD);
        w.set_incr_read(false);
        w.set_incr_write(true);
        w.set_ring_sel(true);
        w.set_ring_size(RING_BITS);
        w.set_treq_sel(TreqSel::UART0_RX);
        w.set_chain_to(channel);
        w.set_irq_quiet(true);
        w.set_en(true);
    });
    // The UART asks the DMA for every character it receives.
    regs.uartdmacr().write(|w| w.set_rxdmae(true));
    regs.uartimsc().write(|w| w.set_txim(false));
    interrupt::UART0_IRQ.set_priority(PORT_PRIORITY);
    interrupt::UART0_IRQ.unpend();
    // Note(unsafe): the handler below shares the transmit buffer through a
    // critical section only.
    unsafe { interrupt::UART0_IRQ.enable() };
    // The alarm that looks at the ring, at the ports' priority.
    TIMER.inte().modify(|w| w.set_alarm(ALARM, true));
    TIMER_LOOK.set_priority(PORT_PRIORITY);
    // Note(unsafe): its handler shares only atomics and a signal.
    unsafe { TIMER_LOOK.enable() };
    arm();
    UartPort {
        channel,
        count: START,
        written: 0,
        taken: 0,
    }
}

/// The chip's timer, and the interrupt of its alarm [`ALARM`].
#[cfg(feature = "rp2040")]
use {embassy_rp::interrupt::TIMER_IRQ_1 as TIMER_LOOK, pac::TIMER};
#[cfg(feature = "rp235xa")]
use {embassy_rp::interrupt::TIMER0_IRQ_1 as TIMER_LOOK, pac::TIMER0 as TIMER};

/// Sets the alarm [`POLL`] from now.
fn arm() {
    let now = TIMER.timerawl().read();
    TIMER
        .alarm(ALARM)
        .write_value(now.wrapping_add(POLL.as_micros() as u32));
}

/// The DMA's transfer count now.
fn dma_count(ch: pac::dma::Channel) -> u32 {
    #[cfg(feature = "rp2040")]
    let count = ch.trans_count().read();
    #[cfg(feature = "rp235xa")]
    let count = ch.trans_count().read().count();
    count
}

#[cfg(feature = "rp2040")]
#[embassy_rp::interrupt]
unsafe fn TIMER_IRQ_1() {
    look_at_ring();
}

#[cfg(feature = "rp235xa")]
#[embassy_rp::interrupt]
unsafe fn TIMER0_IRQ_1() {
    look_at_ring();
}

/// The alarm: wakes the console task if characters came since it last
/// looked, and looks again in [`POLL`].
fn look_at_ring() {
    TIMER.intr().write(|w| w.set_alarm(ALARM, true));
    arm();
    let ch = pac::DMA.ch(usize::from(CHANNEL.load(Ordering::Relaxed)));
    let count = dma_count(ch);
    // (The alarm's handler is the one writer.)
    if LOOKED.load(Ordering::Relaxed) != count || count == 0 {
        LOOKED.store(count, Ordering::Relaxed);
        RX_CAME.signal(());
    }
}

/// Loads the DMA's transfer count and starts it.
fn set_count(ch: pac::dma::Channel) {
    #[cfg(feature = "rp2040")]
    ch.trans_count().write_value(START);
    #[cfg(feature = "rp235xa")]
    ch.trans_count().write(|w| w.set_count(START));
}

/// UART0 as a console [`Port`]: always there.
pub struct UartPort {
    channel: u8,
    /// The DMA's transfer count when last read.
    count: u32,
    /// Characters the DMA has written, and the console has taken (wrapping).
    written: u32,
    taken: u32,
}

impl UartPort {
    /// Counts what the DMA wrote since the last look; restarts it when its
    /// count ran out (at 115200 baud, after days of input).
    fn look(&mut self) {
        let ch = pac::DMA.ch(usize::from(self.channel));
        let count = dma_count(ch);
        self.written = self.written.wrapping_add(self.count.wrapping_sub(count));
        self.count = count;
        if count == 0 && !ch.ctrl_trig().read().busy() {
            set_count(ch);
            ch.ctrl_trig().modify(|w| w.set_en(true));
            self.count = START;
        }
    }

    /// Reads the characters waiting into `buf`: bytes up to the first
    /// damaged character, or that one as [`Received::Lost`]; `None` if none
    /// waits.
    fn take(&mut self, buf: &mut [u8]) -> Option<Received> {
        let waiting = self.written.wrapping_sub(self.taken);
        if waiting as usize > RX_CHARS {
            // Lapped: the oldest characters were written over. Skip to half
            // a ring behind the DMA, clear of where it writes.
            self.taken = self.written.wrapping_sub(RX_CHARS as u32 / 2);
            return Some(Received::Lost);
        }
        let ring = RX_RING.0.get().cast::<u16>();
        let mut n = 0;
        for slot in buf.iter_mut().take(waiting as usize) {
            let at = self.taken as usize % RX_CHARS;
            // Note(unsafe): `at` is within the ring; the DMA writes it
            // concurrently, whole characters at a time.
            let char = unsafe { ptr::read_volatile(ring.add(at)) };
            if char & ERRORS != 0 {
                if n == 0 {
                    self.taken = self.taken.wrapping_add(1);
                    return Some(Received::Lost);
                }
                break;
            }
            *slot = char as u8;
            n += 1;
            self.taken = self.taken.wrapping_add(1);
        }
        (n > 0).then_some(Received::Bytes(n))
    }
}

impl Port for UartPort {
    async fn read(&mut self, buf: &mut [u8]) -> Result<Received, Gone> {
        loop {
            self.look();
            if let Some(received) = self.take(buf) {
                if received == Received::Lost {
                    defmt::warn!("console uart: received bytes lost or damaged");
                }
                return Ok(received);
            }
            RX_CAME.wait().await;
        }
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Gone> {
        let mut rest = bytes;
        loop {
            let (taken, queued) = TX.lock(|tx| {
                let mut tx = tx.borrow_mut();
                let regs = pac::UART0;
                // With nothing queued before them, bytes go straight into
                // the transmit FIFO while it has room (a short reply fits
                // whole: no interrupt needed).
                let mut direct = 0;
                if tx.is_empty() {
                    for &byte in rest {
                        if regs.uartfr().read().txff() {
                            break;
                        }
                        regs.uartdr().write(|w| w.set_data(byte));
                        direct += 1;
                    }
                }
                let later = rest.get(direct..).unwrap_or_default();
                let queued = later.iter().take_while(|&&b| tx.push_back(b).is_ok());
                (direct + queued.count(), !tx.is_empty())
            });
            rest = rest.get(taken..).unwrap_or_default();
            if queued {
                // The interrupt moves them into the FIFO (it only comes by
                // itself once the FIFO drains to its trigger level).
                pac::UART0.uartimsc().modify(|w| w.set_txim(true));
                interrupt::UART0_IRQ.pend();
            }
            if rest.is_empty() {
                return Ok(());
            }
            TX_ROOM.wait().await;
        }
    }
}

#[embassy_rp::interrupt]
unsafe fn UART0_IRQ() {
    let regs = pac::UART0;
    let moved = TX.lock(|tx| {
        let mut tx = tx.borrow_mut();
        let mut moved = false;
        while !regs.uartfr().read().txff() {
            let Some(byte) = tx.pop_front() else { break };
            regs.uartdr().write(|w| w.set_data(byte));
            moved = true;
        }
        if tx.is_empty() {
            regs.uartimsc().modify(|w| w.set_txim(false));
        }
        moved
    });
    regs.uarticr().write(|w| w.set_txic(true));
    // Only room made wakes the writer: the writer pends this interrupt
    // itself, and a signal with the FIFO still full would send it round
    // again at once, spinning until the line drains.
    if moved {
        TX_ROOM.signal(());
    }
}
