//! SysTick as the time base of the QEMU image: a stopwatch for the boot
//! precompute, then the `embassy-time` driver.
//!
//! SysTick is a 24-bit down-counter. It is extended to 64 bits in software:
//! the SysTick exception fires each time the counter wraps and counts the
//! wraps; [`counts`] adds the wraps to the counter value, correcting for a wrap
//! that has happened but whose exception has not run yet (`ICSR.PENDSTSET`).
//!
//! # Clock arithmetic
//!
//! - SysTick counts the core clock of the emulated LM3S6965: 12.5 MHz,
//!   i.e. 80 ns per count.
//! - Under `qemu-system-arm -icount shift=0` one guest instruction advances the
//!   virtual clock by 2^0 ns = 1 ns, so one count is exactly 80 instructions
//!   and a count delta is an instruction count: `insns = counts * 80`.
//! - `embassy-time` runs at 1 MHz (`tick-hz-1_000_000`, the Pico's rate too;
//!   `embassy-time-driver` 0.2 has no 12.5 MHz rate): `µs = counts * 2 / 25`
//!   (12.5 counts per µs), floored, so still monotonic.
//!
//! # Alarms
//!
//! SysTick has no compare register, so the driver runs it with a short fixed
//! period, [`DRIVER_PERIOD`] = 1250 counts = 100 µs, and checks the earliest
//! timer of the embassy queue in every wrap exception. A timer therefore fires
//! between 0 and 100 µs after its deadline (the smoke run's frames are 1 ms).
//! The cost is one short exception per 100 µs (100 000 instructions under
//! `-icount shift=0`), about 0.1 % of the core. Each wrap is also a timer
//! event for QEMU: a 10 µs period made the whole run four times slower on
//! the wall clock for the same log. The precompute measurement runs before
//! this mode starts (see [`stopwatch`]).

use core::cell::RefCell;
use core::task::Waker;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{SCB, SYST};
use cortex_m_rt::exception;
use critical_section::{CriticalSection, Mutex};
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;

/// SysTick input clock: the emulated core clock, 12.5 MHz.
pub const SYSTICK_HZ: u32 = 12_500_000;

/// Guest instructions per SysTick count under `-icount shift=0`:
/// 1 instruction = 1 ns, 1 count = 1 s / 12.5 MHz = 80 ns.
pub const INSNS_PER_COUNT: u64 = 1_000_000_000 / SYSTICK_HZ as u64;

/// SysTick counts per wrap while the embassy time driver runs:
/// 12.5 MHz * 100 µs = 1250 counts. Also the alarm resolution.
pub const DRIVER_PERIOD: u32 = 1250;

/// SysTick counts per wrap for the stopwatch: the full 24-bit range,
/// 2^24 / 12.5 MHz = 1.34 s between wrap exceptions (negligible overhead).
const STOPWATCH_PERIOD: u32 = 1 << 24;

// The embassy tick rate this driver converts to.
const _: () = assert!(embassy_time_driver::TICK_HZ == 1_000_000);
// A whole number of embassy ticks per driver period: 1250 * 2 / 25 = 100 µs.
const _: () = assert!((DRIVER_PERIOD as u64 * 2).is_multiple_of(25));

/// The wrap counter and the timer queue, shared by thread mode and the
/// SysTick exception.
struct SysTickDriver {
    state: Mutex<RefCell<State>>,
}

struct State {
    /// SysTick counts per wrap (reload value + 1).
    period: u32,
    /// Number of wraps since [`restart`].
    wraps: u64,
    /// Whether the embassy driver mode is running (`now()` reads 0 before).
    running: bool,
    /// Earliest timer deadline in µs (`u64::MAX`: none).
    alarm: u64,
    queue: Queue,
}

embassy_time_driver::time_driver_impl!(static DRIVER: SysTickDriver = SysTickDriver {
    state: Mutex::new(RefCell::new(State {
        period: STOPWATCH_PERIOD,
        wraps: 0,
        running: false,
        alarm: u64::MAX,
        queue: Queue::new(),
    })),
});

/// Counts since the last [`restart`], extended to 64 bits.
fn counts(cs: CriticalSection<'_>) -> u64 {
    let state = DRIVER.state.borrow_ref(cs);
    let reload = state.period - 1;
    // Interrupts are masked, so the wrap exception cannot run in between: a
    // wrap shows as PENDSTSET (if it happened before that read) or as the
    // down-counter having gone up between the two reads. At most one wrap can
    // happen here (a period is 100 000 instructions or more, this is a dozen).
    let v1 = SYST::get_current();
    let pending = SCB::is_pendst_pending();
    let v2 = SYST::get_current();
    let wraps = state.wraps + u64::from(pending || v2 > v1);
    wraps * u64::from(state.period) + u64::from(reload - v2)
}

/// SysTick counts since the time base started (the precompute stopwatch or
/// the time driver), for cost measurements: 80 instructions per count under
/// `-icount shift=0`.
pub fn now_counts() -> u64 {
    critical_section::with(counts)
}

/// Converts SysTick counts to embassy ticks (µs): 12.5 counts per µs.
const fn counts_to_us(counts: u64) -> u64 {
    counts * 2 / 25
}

/// Stops SysTick, sets its period, clears the wrap count and starts it again
/// with the wrap exception enabled.
fn restart(syst: &mut SYST, cs: CriticalSection<'_>, period: u32, running: bool) {
    syst.disable_counter();
    syst.disable_interrupt();
    {
        let mut state = DRIVER.state.borrow_ref_mut(cs);
        state.period = period;
        state.wraps = 0;
        state.running = running;
        state.alarm = u64::MAX;
    }
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(period - 1);
    // Writing CVR clears it (and COUNTFLAG); the next count reloads it from
    // RVR. That reload is count 0 of the new time base: wait for it (one
    // count, 80 instructions), so that [`counts`] never sees the cleared 0
    // followed by the reload value, which would look like a wrap.
    syst.clear_current();
    syst.enable_counter();
    while SYST::get_current() == 0 {}
    // A wrap exception pended by the old configuration, or by the reload
    // above, would count a wrap that did not happen in the new time base.
    SCB::clear_pendst();
    syst.enable_interrupt();
}

/// Runs `f` and returns its result with the number of SysTick counts it took.
///
/// SysTick runs with its full 24-bit period and counts wraps in its
/// exception (one per 1.34 s), so the overhead inside the measurement is a
/// few dozen instructions per 1.34 s of run time. Under `-icount shift=0`
/// multiply by [`INSNS_PER_COUNT`] for instructions; the result repeats
/// exactly run after run.
pub fn stopwatch<R>(syst: &mut SYST, f: impl FnOnce() -> R) -> (R, u64) {
    let start = critical_section::with(|cs| {
        restart(syst, cs, STOPWATCH_PERIOD, false);
        counts(cs)
    });
    let result = f();
    let end = critical_section::with(counts);
    (result, end - start)
}

/// SysTick counts per wrap in an interactive run (`console.rs`): 1 ms,
/// the alarm resolution. Its frames are 20 ms apart in real time, and
/// under `-icount sleep=on` every wake-up from `WFI` costs QEMU real time
/// that the virtual clock does not see: at one every 100 µs the virtual
/// clock ran at little more than half the wall clock's pace, at one a
/// millisecond it keeps up.
pub const INTERACTIVE_PERIOD: u32 = 12_500;
const _: () = assert!((INTERACTIVE_PERIOD as u64 * 2).is_multiple_of(25));

/// Starts the embassy time driver on SysTick, wrapping every `period`
/// counts ([`DRIVER_PERIOD`], or [`INTERACTIVE_PERIOD`]); embassy time
/// starts at 0.
///
/// Before this call `embassy_time::Instant::now()` reads 0.
pub fn start_time_driver(syst: &mut SYST, period: u32) {
    critical_section::with(|cs| restart(syst, cs, period, true));
}

impl SysTickDriver {
    /// Arms the alarm for `at`; returns `false` if `at` has already passed
    /// (the caller then dequeues the expired timers and tries the next one).
    fn set_alarm(&self, cs: CriticalSection<'_>, at: u64) -> bool {
        let now = self.now_cs(cs);
        let mut state = self.state.borrow_ref_mut(cs);
        if at <= now {
            state.alarm = u64::MAX;
            false
        } else {
            state.alarm = at;
            true
        }
    }

    /// Wakes the expired timers and arms the alarm for the next one.
    fn expire(&self, cs: CriticalSection<'_>) {
        loop {
            let now = self.now_cs(cs);
            let next = self.state.borrow_ref_mut(cs).queue.next_expiration(now);
            if self.set_alarm(cs, next) {
                break;
            }
        }
    }

    fn now_cs(&self, cs: CriticalSection<'_>) -> u64 {
        if self.state.borrow_ref(cs).running {
            counts_to_us(counts(cs))
        } else {
            0
        }
    }

    /// The wrap exception: one more wrap, then fire the alarm if it is due.
    fn on_wrap(&self) {
        critical_section::with(|cs| {
            let alarm = {
                let mut state = self.state.borrow_ref_mut(cs);
                state.wraps += 1;
                state.alarm
            };
            if alarm != u64::MAX && alarm <= self.now_cs(cs) {
                self.expire(cs);
            }
        });
    }
}

impl Driver for SysTickDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.now_cs(cs))
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            let changed = self.state.borrow_ref_mut(cs).queue.schedule_wake(at, waker);
            if changed {
                self.expire(cs);
            }
        });
    }
}

#[exception]
fn SysTick() {
    DRIVER.on_wrap();
}

/// The loop generator's stopwatch on the running time base, in
/// instructions (80 a SysTick count under `-icount shift=0`). The
/// generator runs in thread mode: whatever preempts it (a UART interrupt)
/// is counted too; at loop set 0 no frame runs yet.
pub struct Instructions;

impl idle_head_firmware::boot::Stopwatch for Instructions {
    fn time<R>(&mut self, work: impl FnOnce() -> R) -> (R, u64) {
        let start = now_counts();
        let result = work();
        (result, (now_counts() - start) * INSNS_PER_COUNT)
    }

    fn unit(&self) -> &'static str {
        "instructions"
    }
}
