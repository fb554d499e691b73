//! The frame benchmark: exact instruction counts of one frame update,
//! [`FrameLoop::write`] (playback, fade, limits, mapping, the three PWM
//! writes), for every frame of a whole loop with the seam and the fade-in,
//! at 50 Hz and at 333 Hz (`servo rate`).
//!
//! # Setting
//!
//! The default driver configuration and playback of the Pico (30 s loops of
//! the Table 2 set, a 2 s fade-in), the never-repeating idle: loop set 0
//! (the default set, checked against the benchmark rows' checksum) and loop
//! set 1 of its stream, generated before (its generation is counted too, as
//! `stream set`), handed over on the frame its join is due. Three PWM
//! channels that accept every duty (the Pico's counts per period: 64 000 at
//! 50 Hz, 60 060 at 333 Hz). At 50 Hz, frames 0 (the start, neutral
//! pulses) to 1600: the fade-in, the join over frames 1400..1500 (set 1
//! taken over at 1400 = 28 s, its join samples read until frame 1502) and
//! 100 frames past it. At 333 Hz (3003 µs), the same times in 1601
//! frames: those of the first 2.1 s (the start and the fade-in) and from
//! 27.7 s on (the join and past it); the frames between are played, not
//! measured. No logging.
//!
//! # Method
//!
//! Under `-icount shift=0` one instruction takes 1 ns of virtual time.
//! SysTick counts the system clock, 12.5 MHz after reset (80 instructions a
//! count, too coarse for a frame of a thousand); the benchmark sets the
//! LM3S6965's clock divider to 1 (`RCC.SYSDIV`, 200 MHz: 5 instructions a
//! count) and checks the new rate on a busy loop timed at both rates. A single reading is still off by up to a count, so each frame
//! is measured by repetition: `reps` fresh copies of the whole state
//! (frame loop and driver), each followed by the frame update, are timed for
//! `reps` = 4 and 36. The difference divided by 32 is the cost of one copy
//! and one update, within ±10/32 instructions of the two readings' rounding:
//! rounded, exact. The fixed costs (timer reads, loop set-up) cancel in the
//! difference. The copies alone are measured the same way (their cost must
//! be the same for every frame, which the benchmark checks) and subtracted.
//! After measuring, the frame is written once more to the real state, so
//! frame `k` is measured in the state frames `0..k` left.
//!
//! What is counted is the call of `FrameLoop::write` as a caller makes it:
//! the argument set-up, the call, its body and the return.
//!
//! ```text
//! stream set=1 insns=<insns>
//! frame bench rate=50 frames=<n> min=<insns> median=<insns> max=<insns> max_at=<frame> mean=<insns>
//! frame bench rate=50 scenario=gesture+look frames=<n> min=<insns> ...
//! frame bench rate=333 frames=<n> ...
//! frame bench rate=333 scenario=gesture+look frames=<n> ...
//! ```
//!
//! The second line measures the same frames with a gesture and a gaze move
//! playing at every one of them: before each frame (not counted), a new
//! gesture starts when the last one has ended (nod, shake, tilt in turn, at
//! their defaults) and a new look (to one of two targets, `hold=stay`)
//! when the head has arrived. Its frames include the limit switches of the
//! roll axis between the idle and the gesture mode.
//!
//! (QEMU 7.2 prints "Timer with period zero, disabling" once when the clock
//! changes; the clock check shows the new rate is the one counted with.)

use core::hint::black_box;

use cortex_m::peripheral::SYST;
use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use idle_head_core::behaviour::Applied;
use idle_head_core::command::{Action, GestureKind, GestureRequest, Hold, LookRequest};
use idle_head_core::driver::{DriverConfig, DriverParams, FrameDriver, FrameTick};
use idle_head_core::idle::{IdleMode, IdlePlayer, IdleTiming, LoopStream, LoopSupply};
use idle_head_core::motion::DEFAULT_HEAD;
use idle_head_core::pwm_clock::{PICO_SYS_HZ, SliceClock};
use idle_head_core::servo::ServoRate;
use idle_head_core::units::Angle;
use idle_head_firmware::config::{DEFAULT_BEHAVIOUR, DEFAULT_TIMING};
use idle_head_firmware::frame::FrameLoop;

use crate::systick;

/// Frames measured: the start frame, the fade-in (frames 1..=100), the
/// join (frames 1400..1500) and 100 frames past it.
const FRAMES: usize = 1601;

/// The repetition counts whose difference is measured.
const FEW: u32 = 4;
const MANY: u32 = 36;

/// Instructions per SysTick count at the 200 MHz clock.
const INSNS_PER_FAST_COUNT: u64 = 5;

/// The LM3S6965's run-mode clock configuration register; bits 26:23 are
/// the system clock divider less one.
const SYSCTL_RCC: *mut u32 = 0x400F_E060 as *mut u32;
const RCC_SYSDIV: u32 = 0xF << 23;

const TIMING: IdleTiming = DEFAULT_TIMING;

/// The rates measured, and for each the frames' times left unmeasured
/// (µs): none at 50 Hz (1601 frames are 32 s), the middle of the loop at
/// 333 Hz (the fade-in and the join are measured, as at 50 Hz).
const RATES: [(u16, core::ops::Range<u64>); 2] = [(50, 0..0), (333, 2_100_000..27_700_000)];

/// A loop set of the default length.
pub use idle_head_firmware::config::Set;

/// Hands loop set 1 over when its join is due; a set given back is dropped.
#[derive(Clone, Copy)]
struct Ready<'a>(Option<&'a Set>);

impl<'a> LoopSupply<&'a Set> for Ready<'a> {
    fn take(&mut self) -> Option<&'a Set> {
        self.0.take()
    }

    fn give_back(&mut self, _set: &'a Set) {}
}

/// A PWM channel that accepts every duty, with the Pico's counts per
/// period (its `TOP`).
#[derive(Clone)]
struct AcceptAll(u16, u16);

impl ErrorType for AcceptAll {
    type Error = core::convert::Infallible;
}

impl SetDutyCycle for AcceptAll {
    fn max_duty_cycle(&self) -> u16 {
        self.1
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        self.0 = duty;
        Ok(())
    }
}

/// Everything a frame update reads and writes.
#[derive(Clone)]
struct State<'a> {
    frames: FrameLoop<'a, IdlePlayer<&'a Set, Ready<'a>>>,
    driver: FrameDriver<AcceptAll>,
}

/// `reps` fresh copies of `saved`.
#[inline(never)]
fn copies(reps: u32, saved: &State<'_>) {
    for _ in 0..reps {
        let mut state = saved.clone();
        black_box(&mut state);
    }
}

/// `reps` fresh copies of `saved`, each with frame `tick` written.
#[inline(never)]
fn copies_and_frames(reps: u32, saved: &State<'_>, tick: FrameTick) {
    for _ in 0..reps {
        let mut state = saved.clone();
        black_box(&mut state);
        let written = state.frames.write(&mut state.driver, tick);
        black_box(&written);
    }
}

/// Instructions of one repetition of `f` (see the module docs).
fn per_rep(syst: &mut SYST, mut f: impl FnMut(u32)) -> u64 {
    let ((), few) = systick::stopwatch(syst, || f(FEW));
    let ((), many) = systick::stopwatch(syst, || f(MANY));
    let insns = many.saturating_sub(few) * INSNS_PER_FAST_COUNT;
    let reps = u64::from(MANY - FEW);
    (insns + reps / 2) / reps
}

/// Instructions of the clock check's busy loop (at least).
const BUSY: u32 = 200_000;

/// Generates loop sets 0 and 1 into `sets`, measures every frame and logs
/// the `stream set` and `frame bench` lines; `default_checksum` is the
/// checksum of the default set, which set 0 must have. `false` if the
/// measurement cannot be trusted.
pub fn run(syst: &mut SYST, sets: &mut [Set; 2], default_checksum: u32) -> bool {
    let [first, second] = sets;
    let mut stream = LoopStream::new(DEFAULT_HEAD, &TIMING);
    if stream.next_into(first).is_err() || first.checksum() != default_checksum {
        defmt::error!("frame bench: loop set 0 is not the default set");
        return false;
    }
    let (next, counts) = systick::stopwatch(syst, || stream.next_into(second));
    if next.is_err() {
        defmt::error!("frame bench: loop set 1 failed");
        return false;
    }
    defmt::info!(
        "stream set=1 insns={=u64}",
        counts * systick::INSNS_PER_COUNT
    );
    let (first, second): (&Set, &Set) = (first, second);
    let ((), coarse) = systick::stopwatch(syst, || cortex_m::asm::delay(BUSY));
    syst.disable_counter();
    // Note(unsafe): RCC is a plain read-write register of the emulated
    // system control block, and nothing else in this image reads the clock.
    unsafe {
        let rcc = SYSCTL_RCC.read_volatile();
        SYSCTL_RCC.write_volatile(rcc & !RCC_SYSDIV);
    }
    let ((), fine) = systick::stopwatch(syst, || cortex_m::asm::delay(BUSY));
    let (coarse, fine) = (
        coarse * systick::INSNS_PER_COUNT,
        fine * INSNS_PER_FAST_COUNT,
    );
    if fine.abs_diff(coarse) > systick::INSNS_PER_COUNT {
        defmt::error!(
            "frame bench: a busy loop took {=u64} instructions at 5 a count, {=u64} at 80",
            fine,
            coarse
        );
        return false;
    }
    for (hz, skip) in RATES {
        // One state and one table of counts on the stack at a time.
        let ok = state_at(hz, first, second)
            .is_some_and(|state| measure(syst, state, hz, &skip, None, &mut |_, _| {}));
        let mut busy = Busy::default();
        let keep = &mut |state: &mut State<'_>, at: u64| busy.keep(state, at);
        if !ok
            || !state_at(hz, first, second)
                .is_some_and(|state| measure(syst, state, hz, &skip, Some("gesture+look"), keep))
        {
            defmt::error!("frame bench: the frames at {=u16} Hz were not measured", hz);
            return false;
        }
    }
    true
}

/// The frame loop and the driver of the default configuration at `hz`,
/// playing loop set `first`, then `second`.
fn state_at<'a>(hz: u16, first: &'a Set, second: &'a Set) -> Option<State<'a>> {
    let period = ServoRate::new(hz)?.period();
    let mut config = DriverConfig::DEFAULT;
    config.frame_period = period;
    config.pwm.period = period;
    let params: DriverParams = config.build().ok()?;
    // The built-in behaviour at that rate, as `servo rate` makes it.
    let mut behaviour = DEFAULT_BEHAVIOUR;
    behaviour.set_frame_period(period);
    let timing = IdleTiming {
        playback: TIMING.playback.with_frame_period(period),
        ..TIMING
    };
    let idle = IdlePlayer::new(first, Ready(Some(second)), timing, IdleMode::NeverRepeating);
    let frames = FrameLoop::with_behaviour(idle, period, behaviour, 1_000_000, 0).ok()?;
    let top = SliceClock::for_period(PICO_SYS_HZ, period).ok()?.top;
    Some(State {
        frames,
        driver: FrameDriver::new(
            [AcceptAll(0, top), AcceptAll(0, top), AcceptAll(0, top)],
            params,
        ),
    })
}

/// The looks' targets `(pitch, yaw)` in degrees: with the idle loops and the
/// default gestures on top, the head stays inside its limits.
const TARGETS: [(i32, i32); 2] = [(-6, 12), (0, -5)];

/// Keeps a gesture and a gaze move playing (see the module docs).
#[derive(Default)]
struct Busy {
    /// The times (µs) the gesture and the look end.
    gesture_until: u64,
    look_until: u64,
    gestures: u32,
    looks: u32,
}

impl Busy {
    /// Starts what has ended before the frame at `at` µs.
    fn keep(&mut self, state: &mut State<'_>, at: u64) {
        if at >= self.gesture_until {
            let kind = [GestureKind::Nod, GestureKind::Shake, GestureKind::Tilt]
                [(self.gestures % 3) as usize];
            self.gestures += 1;
            let action = Action::Gesture(GestureRequest::new(kind));
            if let Ok(Applied::Gesture(plan)) = state.frames.apply(&mut state.driver, &action) {
                self.gesture_until = at + u64::from(plan.duration.0) * 1000;
            }
        }
        if at >= self.look_until {
            let (pitch, yaw) = TARGETS[(self.looks % 2) as usize];
            self.looks += 1;
            let action = Action::Look(LookRequest {
                pitch: Angle::from_degrees(pitch),
                yaw: Angle::from_degrees(yaw),
                duration: None,
                hold: Some(Hold::Stay),
            });
            if let Ok(Applied::Look(look)) = state.frames.apply(&mut state.driver, &action) {
                self.look_until = at + u64::from(look.duration.0) * 1000;
            }
        }
    }
}

/// Measures [`FRAMES`] frames of `state` at `hz` (`before` runs,
/// uncounted, before each; the frames whose time lies in `skip` are
/// played, not measured) and logs the `frame bench` line of `scenario`;
/// `false` if the measurement cannot be trusted.
fn measure(
    syst: &mut SYST,
    mut state: State<'_>,
    hz: u16,
    skip: &core::ops::Range<u64>,
    scenario: Option<&str>,
    before: &mut dyn FnMut(&mut State<'_>, u64),
) -> bool {
    // Below 2¹⁶ a frame (the ceilings are 4,000): 3.2 KB of stack.
    let mut insns = [0u16; FRAMES];
    // The costliest frame so far: its count and index.
    let mut costliest = (0, 0);
    // The copy's cost outside and inside the join.
    let mut copy_insns: [Option<u64>; 2] = [None, None];
    for slot in &mut insns {
        let mut tick = state.frames.next(state.frames.deadline());
        while skip.contains(&tick.at.0) {
            before(&mut state, tick.at.0);
            state.frames.drain(&mut state.driver, tick);
            black_box(state.frames.write(&mut state.driver, tick));
            tick = state.frames.next(state.frames.deadline());
        }
        let frame = tick.frame;
        before(&mut state, tick.at.0);
        // Between frames, as the frame task: the limit modes asked for.
        state.frames.drain(&mut state.driver, tick);
        let copy = per_rep(syst, |reps| copies(reps, &state));
        let joining = usize::from(state.frames.idle_mut().in_join());
        let first = *copy_insns[joining].get_or_insert(copy);
        if first != copy {
            defmt::error!(
                "frame bench: frame {=u64}: a copy of the state took {=u64} instructions, before {=u64}",
                frame,
                copy,
                first
            );
            return false;
        }
        let both = per_rep(syst, |reps| copies_and_frames(reps, &state, tick));
        *slot = u16::try_from(both.saturating_sub(copy)).unwrap_or(u16::MAX);
        if *slot > costliest.0 {
            costliest = (*slot, frame);
        }
        black_box(state.frames.write(&mut state.driver, tick));
    }
    let idle = state.frames.idle_mut().stats();
    if idle.joins != 1 || idle.set != 1 {
        defmt::error!("frame bench: the measured frames did not join loop set 1");
        return false;
    }
    log(hz, scenario, &mut insns, costliest.1);
    true
}

/// The `frame bench` line of `insns`, the costliest frame being `max_at`
/// (sorted in place: a second table on the stack would leave the frame
/// state too little room).
fn log(hz: u16, scenario: Option<&str>, insns: &mut [u16; FRAMES], max_at: u64) {
    let total: u64 = insns.iter().map(|&n| u64::from(n)).sum();
    let sorted = insns;
    sorted.sort_unstable();
    let max = sorted[FRAMES - 1];
    let (min, median, mean) = (sorted[0], sorted[FRAMES / 2], total / FRAMES as u64);
    match scenario {
        None => defmt::info!(
            "frame bench rate={=u16} frames={=usize} min={=u16} median={=u16} max={=u16} max_at={=u64} mean={=u64}",
            hz,
            FRAMES,
            min,
            median,
            max,
            max_at,
            mean
        ),
        Some(name) => defmt::info!(
            "frame bench rate={=u16} scenario={=str} frames={=usize} min={=u16} median={=u16} max={=u16} max_at={=u64} mean={=u64}",
            hz,
            name,
            FRAMES,
            min,
            median,
            max,
            max_at,
            mean
        ),
    }
}
