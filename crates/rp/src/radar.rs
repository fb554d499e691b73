//! The HLK-LD2450 radar's receiver: its TX on GP13, 256000 baud 8N1,
//! 3.3 V levels, through a PIO state machine (PIO0, SM0; UART0 is the
//! console, UART1 DMX512) whose words a DMA channel copies into a ring in
//! RAM ([`RING`] characters) as they arrive, with neither the CPU nor the
//! flash. A timer alarm at the ports' priority looks at the ring every
//! [`POLL`] and hands what came to the firmware layer's decoder
//! ([`idle_head_firmware::radar::Radar::receive`]); a damaged character,
//! a ring lapped or a stalled state machine is reported as lost bytes
//! ([`idle_head_firmware::radar::Radar::receive_error`]).
//!
//! Invariant: the ring outlasts a typical `save` (every settings sector
//! erased with the interrupts off, the alarm kept waiting); frames lost
//! to a longer one are counted. The program, the ring's sizing and the idle line are in the
//! book's notes on the code (`docs/design/code.md`, "The radar's
//! receiver").

use core::cell::UnsafeCell;
use core::mem::MaybeUninit;
use core::ptr;
use core::sync::atomic::{AtomicU8, AtomicU32, Ordering};

use embassy_rp::Peri;
use embassy_rp::dma::ChannelInstance;
use embassy_rp::gpio::Pull;
use embassy_rp::interrupt::{self, InterruptExt};
use embassy_rp::pac;
use embassy_rp::pac::dma::vals::DataSize;
use embassy_rp::peripherals::PIO0;
use embassy_rp::pio::{
    Common, Config, Direction, FifoJoin, PioPin, ShiftConfig, ShiftDirection, StateMachine,
};
use embassy_time::Duration;
use fixed::FixedU32;
use fixed::types::extra::U8;
use idle_head_firmware::boot::{LINKS, RADAR};

use crate::{PORT_PRIORITY, SYS_HZ};

/// The LD2450's line rate.
pub const BAUD: u32 = 256_000;
/// PIO cycles a bit (the program's timing).
const CYCLES_PER_BIT: u32 = 8;
/// Characters the ring holds: 256 · 39 µs of back-to-back bytes, or eight
/// of the radar's 30-byte frames (0.85 s at its ten a second).
pub const RING: usize = 256;
/// How often the alarm looks at the ring: what a byte waits at most
/// before the decoder sees it.
pub const POLL: Duration = Duration::from_millis(1);

/// The timer alarm that looks at the ring (embassy-time's driver uses 0,
/// UART0's console 1).
const ALARM: usize = 2;
/// The state machine (of PIO0) that receives.
const SM: usize = 0;
/// A character's flag for a low stop bit (the program's bit 8).
const DAMAGED: u16 = 0x100;

/// The ring's size as the DMA counts it: 2^10 bytes of 16-bit words.
const RING_BITS: u8 = 9;
const _: () = assert!(1 << RING_BITS == RING * 2);

/// The words the DMA writes, aligned to their size (the DMA's ring wraps
/// its write address on that boundary). Never read before the DMA wrote
/// it, so it needs no zeroing at reset: in a section of its own,
/// `.radar_ring`, which the board's `memory.x` places first in RAM, where
/// its alignment costs no padding.
#[repr(C, align(512))]
struct Ring(UnsafeCell<MaybeUninit<[u16; RING]>>);

// Note(unsafe): only the DMA writes the ring, and only the alarm's handler
// reads it, with volatile reads of whole words the DMA has written.
unsafe impl Sync for Ring {}

#[unsafe(link_section = ".radar_ring")]
static RX_RING: Ring = Ring(UnsafeCell::new(MaybeUninit::uninit()));

/// The receive DMA channel, for the alarm.
static CHANNEL: AtomicU8 = AtomicU8::new(0);
/// The DMA's transfer count when the alarm last looked.
static COUNT: AtomicU32 = AtomicU32::new(START);
/// Words the DMA has written, and the alarm has taken (wrapping).
static WRITTEN: AtomicU32 = AtomicU32::new(0);
static TAKEN: AtomicU32 = AtomicU32::new(0);

/// The DMA's transfer count at the start: it counts down one a word (at
/// 256000 baud without a pause, a day's worth; the alarm starts it again
/// when it runs out). The RP2350's count field is 28 bits wide.
#[cfg(feature = "rp2040")]
const START: u32 = 0x7fff_ffff;
#[cfg(feature = "rp235xa")]
const START: u32 = 0x0fff_ffff;

/// The state machine's clock divider, 8.8 fixed point: exactly
/// `SYS_HZ / (8 · BAUD)`: 61 + 9/256 at the RP2040's 125 MHz, 73 + 62/256
/// at the RP2350's 150 MHz, both without a remainder.
const DIVIDER: u32 = (SYS_HZ as u64 * 256 / (CYCLES_PER_BIT as u64 * BAUD as u64)) as u32;
const _: () = assert!((SYS_HZ as u64 * 256).is_multiple_of(CYCLES_PER_BIT as u64 * BAUD as u64));

/// The radar's state machine, set up and not yet running ([`listen`]).
pub struct RadarRx {
    sm: StateMachine<'static, PIO0, SM>,
    channel: u8,
}

/// PIO0's state machine 0 set up to receive on `rx` (its pull-up on), and
/// DMA channel `dma` for it; nothing runs until [`listen`]. `None` if the
/// program does not fit PIO0 (it always does: nothing else uses it).
pub fn receiver<D: ChannelInstance>(
    common: &mut Common<'static, PIO0>,
    mut sm: StateMachine<'static, PIO0, SM>,
    rx: Peri<'static, impl PioPin>,
    // The channel is the radar's from now on: its registers are set in
    // `listen`.
    _dma: Peri<'static, D>,
) -> Option<RadarRx> {
    // 8 cycles a bit: the first data bit is sampled 12 cycles after the
    // start bit's edge (its middle), each next one 8 later; the stop bit
    // too, 4 cycles before it ends, so that a sender slightly fast loses
    // nothing.
    let program = embassy_rp::pio::program::pio_asm!(
        ".wrap_target",
        "start:",
        "    wait 0 pin 0",
        "    set x, 7 [10]",
        "bit:",
        "    in pins, 1",
        "    jmp x-- bit [6]",
        "    jmp pin good",
        // The stop bit is low: x is all ones after the loop, so a one
        // goes in as bit 8, the byte's bits below it.
        "    in x, 1",
        "    in null, 23",
        "    push",
        "    wait 1 pin 0",
        "    jmp start",
        "good:",
        "    in null, 24",
        "    push",
        ".wrap",
    );
    let loaded = common.try_load_program(&program.program).ok()?;
    let mut pin = common.make_pio_pin(rx);
    pin.set_pull(Pull::Up);
    let mut config = Config::default();
    config.use_program(&loaded, &[]);
    config.set_in_pins(&[&pin]);
    config.set_jmp_pin(&pin);
    config.clock_divider = FixedU32::<U8>::from_bits(DIVIDER);
    config.shift_in = ShiftConfig {
        threshold: 32,
        direction: ShiftDirection::Right,
        auto_fill: false,
    };
    config.fifo_join = FifoJoin::RxOnly;
    sm.set_config(&config);
    sm.set_pin_dirs(Direction::In, &[&pin]);
    Some(RadarRx {
        sm,
        channel: D::number(),
    })
}

/// Starts receiving: the DMA copies every character into the ring, and the
/// alarm looks at it every [`POLL`], at the ports' priority.
pub fn listen(rx: RadarRx) {
    let RadarRx { mut sm, channel } = rx;
    CHANNEL.store(channel, Ordering::Relaxed);
    let ch = pac::DMA.ch(usize::from(channel));
    ch.read_addr().write_value(sm.rx_fifo_ptr() as u32);
    ch.write_addr().write_value(RX_RING.0.get() as u32);
    set_count(ch);
    let treq = sm.rx_treq();
    ch.ctrl_trig().write(|w| {
        w.set_data_size(DataSize::SIZE_HALFWORD);
        w.set_incr_read(false);
        w.set_incr_write(true);
        w.set_ring_sel(true);
        w.set_ring_size(RING_BITS);
        w.set_treq_sel(treq);
        w.set_chain_to(channel);
        w.set_irq_quiet(true);
        w.set_en(true);
    });
    sm.set_enable(true);
    // The state machine runs for as long as the board does: dropping it
    // would hand its pin back.
    core::mem::forget(sm);
    TIMER.inte().modify(|w| w.set_alarm(ALARM, true));
    TIMER_LOOK.set_priority(PORT_PRIORITY);
    TIMER_LOOK.unpend();
    // Note(unsafe): its handler shares only atomics, the ring (read only)
    // and the decoder behind its critical section.
    unsafe { TIMER_LOOK.enable() };
    arm();
}

/// The chip's timer, and the interrupt of its alarm [`ALARM`].
#[cfg(feature = "rp2040")]
use {embassy_rp::interrupt::TIMER_IRQ_2 as TIMER_LOOK, pac::TIMER};
#[cfg(feature = "rp235xa")]
use {embassy_rp::interrupt::TIMER0_IRQ_2 as TIMER_LOOK, pac::TIMER0 as TIMER};

#[cfg(feature = "rp2040")]
#[embassy_rp::interrupt]
unsafe fn TIMER_IRQ_2() {
    look();
}

#[cfg(feature = "rp235xa")]
#[embassy_rp::interrupt]
unsafe fn TIMER0_IRQ_2() {
    look();
}

/// Sets the alarm [`POLL`] from now.
fn arm() {
    let now = TIMER.timerawl().read();
    TIMER
        .alarm(ALARM)
        .write_value(now.wrapping_add(POLL.as_micros() as u32));
}

/// Loads the DMA's transfer count.
fn set_count(ch: pac::dma::Channel) {
    #[cfg(feature = "rp2040")]
    ch.trans_count().write_value(START);
    #[cfg(feature = "rp235xa")]
    ch.trans_count().write(|w| w.set_count(START));
}

/// The DMA's transfer count now.
fn dma_count(ch: pac::dma::Channel) -> u32 {
    #[cfg(feature = "rp2040")]
    let count = ch.trans_count().read();
    #[cfg(feature = "rp235xa")]
    let count = ch.trans_count().read().count();
    count
}

/// The alarm: hands the characters the DMA wrote since the last look to
/// the decoder, in order, with the damaged ones and any loss reported as
/// errors where they fell; and looks again in [`POLL`].
fn look() {
    TIMER.intr().write(|w| w.set_alarm(ALARM, true));
    arm();
    let ch = pac::DMA.ch(usize::from(CHANNEL.load(Ordering::Relaxed)));
    let count = dma_count(ch);
    // (This handler is the one writer of these.)
    let came = COUNT.load(Ordering::Relaxed).wrapping_sub(count);
    COUNT.store(count, Ordering::Relaxed);
    let written = WRITTEN.load(Ordering::Relaxed).wrapping_add(came);
    WRITTEN.store(written, Ordering::Relaxed);
    let mut taken = TAKEN.load(Ordering::Relaxed);
    if written.wrapping_sub(taken) as usize > RING {
        // Lapped: the oldest were written over. On from half a ring behind
        // the DMA, clear of where it writes.
        taken = written.wrapping_sub(RING as u32 / 2);
        RADAR.receive_error(&LINKS.show.track);
    }
    let ring = RX_RING.0.get().cast::<u16>();
    let mut bytes = [0_u8; 32];
    let mut n = 0;
    while taken != written {
        let at = taken as usize % RING;
        // Note(unsafe): `at` is within the ring; the DMA writes it
        // concurrently, whole words at a time, never this one (it is
        // behind the DMA's count).
        let word = unsafe { ptr::read_volatile(ring.add(at)) };
        taken = taken.wrapping_add(1);
        if word & DAMAGED != 0 {
            if n > 0 {
                RADAR.receive(bytes.get(..n).unwrap_or_default(), &LINKS.show.track);
            }
            n = 0;
            RADAR.receive_error(&LINKS.show.track);
            continue;
        }
        if let Some(slot) = bytes.get_mut(n) {
            *slot = word as u8;
            n += 1;
        }
        if n == bytes.len() {
            RADAR.receive(&bytes, &LINKS.show.track);
            n = 0;
        }
    }
    if n > 0 {
        RADAR.receive(bytes.get(..n).unwrap_or_default(), &LINKS.show.track);
    }
    TAKEN.store(taken, Ordering::Relaxed);
    // A state machine stalled on a full FIFO lost the bytes of that while
    // (the DMA stopped: its count ran out).
    let stalled = 1 << SM;
    if pac::PIO0.fdebug().read().rxstall() & stalled != 0 {
        pac::PIO0.fdebug().write(|w| w.set_rxstall(stalled));
        RADAR.receive_error(&LINKS.show.track);
    }
    if count == 0 && !ch.ctrl_trig().read().busy() {
        set_count(ch);
        ch.ctrl_trig().modify(|w| w.set_en(true));
        COUNT.store(START, Ordering::Relaxed);
    }
}
