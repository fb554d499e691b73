//! The frame benchmark: exact instruction counts of one frame update,
//! [`FrameLoop::write`] (playback, fade, limits, mapping, the three PWM
//! writes), for every frame of a whole loop with the seam and the fade-in.
//!
//! # Setting
//!
//! The default driver configuration and playback of the Pico (50 Hz frames,
//! 30 s loops of the Table 2 set: 1500 frames a loop, a 2 s fade-in), the
//! never-repeating idle: loop set 0 (the default set, checked against the
//! benchmark rows' checksum) and loop set 1 of its stream, generated before
//! (its generation is counted too, as `stream set`), handed over on the
//! frame its join is due. Three PWM channels that accept every duty (the
//! Pico's 64 000 counts per period), frames 0 (the start, neutral pulses) to
//! 1600: the fade-in, the join over frames 1400..1500 (set 1 taken over at
//! 1400, its join samples read until frame 1502) and 100 frames past it. No
//! logging.
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
//! frame bench frames=<n> min=<insns> median=<insns> max=<insns> max_at=<frame> mean=<insns>
//! frame bench scenario=gesture+look frames=<n> min=<insns> ...
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
use idle_head_core::units::Angle;
use idle_head_firmware::config::{DEFAULT_PARAMS, DEFAULT_PLAYBACK, DEFAULT_TIMING};
use idle_head_firmware::frame::FrameLoop;

use idle_head_core::Playback;
use idle_head_core::pwm_clock::PICO_SERVO_CLOCK;

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

const PARAMS: DriverParams = DEFAULT_PARAMS;
const PLAYBACK: Playback = DEFAULT_PLAYBACK;
const TIMING: IdleTiming = DEFAULT_TIMING;

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

/// A PWM channel that accepts every duty, with the Pico's counts per period.
#[derive(Clone)]
struct AcceptAll(u16);

impl ErrorType for AcceptAll {
    type Error = core::convert::Infallible;
}

impl SetDutyCycle for AcceptAll {
    fn max_duty_cycle(&self) -> u16 {
        PICO_SERVO_CLOCK.top
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
    let idle = IdlePlayer::new(first, Ready(Some(second)), TIMING, IdleMode::NeverRepeating);
    let Ok(frames) = FrameLoop::new(idle, PLAYBACK.frame_period(), 1_000_000, 0) else {
        return false;
    };
    let channels = [AcceptAll(0), AcceptAll(0), AcceptAll(0)];
    let state = State {
        frames,
        driver: FrameDriver::new(channels, PARAMS),
    };
    // One table of counts on the stack at a time (6.4 KB each).
    if !measure(syst, state.clone(), None, &mut |_, _| {}) {
        return false;
    }
    let mut busy = Busy::default();
    measure(syst, state, Some("gesture+look"), &mut |state, frame| {
        busy.keep(state, frame);
    })
}

/// The looks' targets `(pitch, yaw)` in degrees: with the idle loops and the
/// default gestures on top, the head stays inside its limits.
const TARGETS: [(i32, i32); 2] = [(-6, 12), (0, -5)];

/// Keeps a gesture and a gaze move playing (see the module docs).
#[derive(Default)]
struct Busy {
    gesture_until: u64,
    look_until: u64,
    gestures: u32,
    looks: u32,
}

impl Busy {
    /// Starts what has ended before frame `frame`.
    fn keep(&mut self, state: &mut State<'_>, frame: u64) {
        let frame_ms = u64::from(DriverConfig::DEFAULT.frame_period.0 / 1000);
        if frame >= self.gesture_until {
            let kind = [GestureKind::Nod, GestureKind::Shake, GestureKind::Tilt]
                [(self.gestures % 3) as usize];
            self.gestures += 1;
            let action = Action::Gesture(GestureRequest::new(kind));
            if let Ok(Applied::Gesture(plan)) = state.frames.apply(&mut state.driver, &action) {
                self.gesture_until = frame + u64::from(plan.duration.0) / frame_ms;
            }
        }
        if frame >= self.look_until {
            let (pitch, yaw) = TARGETS[(self.looks % 2) as usize];
            self.looks += 1;
            let action = Action::Look(LookRequest {
                pitch: Angle::from_degrees(pitch),
                yaw: Angle::from_degrees(yaw),
                duration: None,
                hold: Some(Hold::Stay),
            });
            if let Ok(Applied::Look(look)) = state.frames.apply(&mut state.driver, &action) {
                self.look_until = frame + u64::from(look.duration.0) / frame_ms;
            }
        }
    }
}

/// Measures every frame of `state` (`before` runs, uncounted, before each)
/// and logs the `frame bench` line of `scenario`; `false` if the
/// measurement cannot be trusted.
fn measure(
    syst: &mut SYST,
    mut state: State<'_>,
    scenario: Option<&str>,
    before: &mut dyn FnMut(&mut State<'_>, u64),
) -> bool {
    let mut insns = [0u32; FRAMES];
    // The copy's cost outside and inside the join.
    let mut copy_insns: [Option<u64>; 2] = [None, None];
    for (frame, slot) in insns.iter_mut().enumerate() {
        let tick = state.frames.next(state.frames.deadline());
        before(&mut state, tick.frame);
        // Between frames, as the frame task: the limit modes asked for.
        state.frames.drain(&mut state.driver, tick);
        let copy = per_rep(syst, |reps| copies(reps, &state));
        let joining = usize::from(state.frames.idle_mut().in_join());
        let first = *copy_insns[joining].get_or_insert(copy);
        if first != copy {
            defmt::error!(
                "frame bench: frame {=usize}: a copy of the state took {=u64} instructions, before {=u64}",
                frame,
                copy,
                first
            );
            return false;
        }
        let both = per_rep(syst, |reps| copies_and_frames(reps, &state, tick));
        *slot = both.saturating_sub(copy) as u32;
        black_box(state.frames.write(&mut state.driver, tick));
    }
    let idle = state.frames.idle_mut().stats();
    if idle.joins != 1 || idle.set != 1 {
        defmt::error!("frame bench: the measured frames did not join loop set 1");
        return false;
    }
    log(scenario, &mut insns);
    true
}

/// The `frame bench` line of `insns` (sorted in place: a second table of
/// 6.4 KB on the stack would leave the frame state too little room).
fn log(scenario: Option<&str>, insns: &mut [u32; FRAMES]) {
    let total: u64 = insns.iter().map(|&n| u64::from(n)).sum();
    let max = insns.iter().copied().max().unwrap_or(0);
    let max_at = insns.iter().position(|&n| n == max).unwrap_or(0);
    let sorted = insns;
    sorted.sort_unstable();
    let (min, median, mean) = (sorted[0], sorted[FRAMES / 2], total / FRAMES as u64);
    match scenario {
        None => defmt::info!(
            "frame bench frames={=usize} min={=u32} median={=u32} max={=u32} max_at={=usize} mean={=u64}",
            FRAMES,
            min,
            median,
            max,
            max_at,
            mean
        ),
        Some(name) => defmt::info!(
            "frame bench scenario={=str} frames={=usize} min={=u32} median={=u32} max={=u32} max_at={=usize} mean={=u64}",
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
