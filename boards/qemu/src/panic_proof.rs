//! Link-time proof that the frame path cannot panic.
//!
//! ```text
//! cargo build --release --manifest-path qemu/Cargo.toml --bin frame-path-proof
//! ```
//!
//! (from the repository root; in qemu/, `cargo build --release --bin frame-path-proof`).
//!
//! This image runs the per-frame work of the firmware — [`FrameLoop::next`]
//! (frame clock) and [`FrameLoop::write`] (the never-repeating idle: loop
//! sets taken from and given back to the generator's channels, joins
//! blended; playback interpolation, fade,
//! limits, pulse and duty conversion, PWM writes and fault handling in
//! `FrameDriver::write_frame`) — on inputs the optimiser cannot see
//! through (`core::hint::black_box`): any time, any loop contents, any PWM
//! maximum, PWM writes that fail or not, stop and resume requests at any
//! frame, new motion limits and servo calibrations (any values, valid or
//! not) between any two frames, relax on or off at any frame, and the
//! behaviour: any behaviour parameters and any command (gestures, looks,
//! `center`, idle changes, stop, rest, wake) applied between any two frames
//! ([`FrameLoop::apply`], and through the command queue with any live rest
//! and look settings from the link: [`FrameLoop::drain`]), mixed into every
//! frame, servo calibrations from the console's link, each command's
//! outcome told to the console port that asked for it
//! (`ConsoleLink::answer`, as [`FrameLoop::drain`] does), the status
//! published for it after every frame ([`FrameLoop::publish`]: the
//! pose, the idle and the tracker's view), the telemetry line `watch`
//! writes of it (`idle_head_core::console::telemetry_line`, any people
//! at any positions), the
//! console's parser (`idle_head_core::console::parse`) on any line, the
//! trigger inputs' state machine (`idle_head_core::input::Inputs`) on any
//! levels; the show layer ([`FrameLoop::show`]: any DMX cue, DMX on or off,
//! any Bottango curves sampled at any time, blended into every frame), the
//! DMX receiver (`idle_head_firmware::dmx::Receiver`, the UART interrupt's
//! work: any character, break or error at any address), the radar's
//! receiver (`idle_head_firmware::radar::feed`: the LD2450 decoder on any
//! bytes, any receive error) and the tracker (`FrameLoop::show` hands any
//! sighting, with any tracking settings, to attention and the gaze), the
//! inputs' radar presence (`Inputs::sense`) and Bottango's side
//! of the console (its line parser on any line, any motor command on the
//! shared curves, any curve built from any parameters), and a change of
//! the servos' rate at any frame to any period of the range
//! ([`FrameLoop::take_rate`] before a frame, the frames' part of it in
//! [`FrameLoop::write`]) on outputs that take it or not. Its panic handler calls `frame_path_has_a_panic_path`, a function
//! that exists nowhere. If any panic (index, division, overflow check,
//! `unwrap`, ...) remains reachable after optimisation, the call survives
//! and the link fails:
//!
//! ```text
//! rust-lld: error: undefined symbol: frame_path_has_a_panic_path
//! ```
//!
//! A successful build is the proof, for the release profile the firmware is
//! built with. The image is never run. The driver parameters and the
//! playback are built outside the proof (at compile time, as in the board
//! images); only the frame work is covered.
#![no_std]
#![no_main]

use core::hint::black_box;

use embedded_hal::pwm::{ErrorKind, ErrorType, SetDutyCycle};
use idle_head_core::Millimetres;
use idle_head_core::behaviour::{Asker, CommandQueue, LiveConfig, RestConfig, ShowLink};
use idle_head_core::bottango::{self, Curve, Op, line::CurveArgs};
use idle_head_core::command::{
    Action, GestureKind, GestureRequest, Hold, InputRole, LookRequest, Percent, RestAfter,
};
use idle_head_core::console::{ConsoleLink, TELEMETRY_LINE, parse, telemetry_line};
use idle_head_core::dmx::{DmxAddress, DmxSettings};
use idle_head_core::driver::{
    DegreesPerSecond, DegreesPerSecondSquared, DriverParams, FrameDriver, MotionLimits,
};
use idle_head_core::idle::{IdlePlayer, IdleTiming};
use idle_head_core::input::{InputSettings, Inputs, Micros};
use idle_head_core::servo::{Direction, NanosPerDegree, ServoCalibration, ServoRate, SetPeriod};
use idle_head_core::track::ld2450::Decoder;
use idle_head_core::track::{Person, Prefer, Sighting, SightingSource, TrackSettings, TrackView};
use idle_head_core::units::{Angle, AngleRange, Microseconds, Millis};
use idle_head_core::{Axis, Playback};
use idle_head_firmware::config::{
    DEFAULT_BEHAVIOUR, DEFAULT_PARAMS, DEFAULT_PLAYBACK, DEFAULT_TIMING, IDLE_MODE, Set,
};
use idle_head_firmware::dmx::{Receiver, Rx};
use idle_head_firmware::exchange::Exchange;
use idle_head_firmware::frame::FrameLoop;
use static_cell::ConstStaticCell;

const PARAMS: DriverParams = DEFAULT_PARAMS;
const PLAYBACK: Playback = DEFAULT_PLAYBACK;
const TIMING: IdleTiming = DEFAULT_TIMING;

/// Loop sets with unknown contents (the optimiser sees them through
/// `black_box`).
static SETS: ConstStaticCell<[Set; 2]> = ConstStaticCell::new([Set::new(), Set::new()]);

/// The channels to the generator (none runs: whether a set is ready is
/// unknown to the optimiser).
static EXCHANGE: Exchange = Exchange::new();

/// What the console shares with the frame task: calibrations and live
/// settings in, status out.
static LINK: ConsoleLink = ConsoleLink::new();

/// The show layer's inputs: DMX cues and Bottango's curves in.
static SHOW: ShowLink = ShowLink::new();

/// Actions from the console ports and the inputs, which `drain` takes.
static COMMANDS: CommandQueue = CommandQueue::new();

/// Any curve parameters.
fn any_curve() -> Curve {
    let n = || black_box(0_i32);
    Curve::new(
        black_box(0),
        &CurveArgs {
            start: n(),
            duration: black_box(0),
            start_y: n(),
            start_control: (n(), n()),
            end_y: n(),
            end_control: (n(), n()),
        },
    )
}

/// A PWM channel whose maximum duty and write results are unknown.
struct OpaquePwm;

impl ErrorType for OpaquePwm {
    type Error = ErrorKind;
}

impl SetDutyCycle for OpaquePwm {
    fn max_duty_cycle(&self) -> u16 {
        black_box(u16::MAX)
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        if black_box(duty) == black_box(0) {
            Err(ErrorKind::Other)
        } else {
            Ok(())
        }
    }
}

impl SetPeriod for OpaquePwm {
    fn set_period(&mut self, period: Microseconds) -> Result<(), Self::Error> {
        if black_box(period.0) == black_box(0) {
            Err(ErrorKind::Other)
        } else {
            Ok(())
        }
    }
}

/// The log goes nowhere: the proof covers what the frame path formats for
/// its log (the drain logs every action with its answer), not a transport.
#[defmt::global_logger]
struct Nowhere;

// Note(unsafe): defmt's logger contract (acquire, write, flush, release in
// order, one at a time) holds trivially for a logger that does nothing.
unsafe impl defmt::Logger for Nowhere {
    fn acquire() {}
    unsafe fn flush() {}
    unsafe fn release() {}
    unsafe fn write(bytes: &[u8]) {
        black_box(bytes);
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    unsafe extern "C" {
        /// Defined nowhere: the proof.
        fn frame_path_has_a_panic_path() -> !;
    }
    // Note(unsafe): never executed; the image only links if no call to this
    // handler is left.
    unsafe { frame_path_has_a_panic_path() }
}

/// Any command, with any values.
fn any_action() -> Action {
    let angle = || Angle::from_millidegrees(black_box(0));
    let millis = || black_box(Some(Millis(black_box(0))));
    match black_box(0_u8) {
        0 => Action::Gesture(GestureRequest {
            // Every row of the gesture table.
            kind: GestureKind::ALL[usize::from(black_box(0_u8)) % GestureKind::COUNT],
            amplitude: black_box(Some(angle())),
            duration: millis(),
            cycles: black_box(Some(black_box(0))),
            intensity: Percent::new(black_box(0)),
        }),
        1 => Action::Look(LookRequest {
            pitch: angle(),
            yaw: angle(),
            duration: millis(),
            hold: match black_box(0_u8) {
                0 => None,
                1 => Some(Hold::Stay),
                _ => Some(Hold::Return(Millis(black_box(0)))),
            },
        }),
        2 => Action::Center { duration: millis() },
        3 => Action::Idle(black_box(false)),
        4 => Action::IdleAmp(Percent::new(black_box(0)).unwrap_or(Percent::FULL)),
        5 => Action::Rest,
        6 => Action::Wake {
            toward: black_box(Some(angle())),
        },
        _ => Action::Stop,
    }
}

/// Any live behaviour settings: any rest pose, relax or not, any duck.
fn any_live() -> LiveConfig {
    let angle = || Angle::from_millidegrees(black_box(0));
    LiveConfig {
        rest: RestConfig {
            pose: [angle(), angle(), angle()],
            relax: black_box(false),
        },
        look_duck: Percent::new(black_box(0)).unwrap_or(Percent::FULL),
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some([first, second]) = black_box(SETS.try_take()) else {
        loop {
            cortex_m::asm::wfi();
        }
    };
    EXCHANGE.give(black_box(second));
    let idle = IdlePlayer::new(first, EXCHANGE.supply(), black_box(TIMING), IDLE_MODE);
    let mut driver = FrameDriver::new([OpaquePwm, OpaquePwm, OpaquePwm], black_box(PARAMS));
    let Ok(mut frames) = FrameLoop::with_behaviour(
        idle,
        black_box(PLAYBACK.frame_period()),
        black_box(DEFAULT_BEHAVIOUR),
        black_box(1_000_000),
        black_box(0),
    )
    .map(|frames| {
        frames
            .with_commands(&COMMANDS)
            .with_link(&LINK)
            .with_show(&SHOW)
    }) else {
        // Not reached with the built-in playback; no panic either way.
        loop {
            cortex_m::asm::wfi();
        }
    };
    let mut receiver = Receiver::new();
    let mut radar = Decoder::new();
    let mut inputs = Inputs::new(&InputSettings::DEFAULT, Micros(0));
    loop {
        let axis = Axis::ALL[usize::from(black_box(0_u8) % 3)];
        match black_box(0_u8) {
            1 => driver.request_stop(),
            2 => driver.resume(),
            3 => {
                let limits = MotionLimits {
                    max_speed: DegreesPerSecond(black_box(0)),
                    max_accel: DegreesPerSecondSquared(black_box(0)),
                };
                black_box(driver.set_motion_limits(axis, limits)).ok();
            }
            4 => {
                let cal = ServoCalibration {
                    neutral: Microseconds(black_box(0)),
                    per_degree: NanosPerDegree(black_box(0)),
                    direction: if black_box(false) {
                        Direction::Reversed
                    } else {
                        Direction::Normal
                    },
                    min_pulse: Microseconds(black_box(0)),
                    max_pulse: Microseconds(black_box(0)),
                    limits: AngleRange {
                        min: Angle::from_millidegrees(black_box(0)),
                        max: Angle::from_millidegrees(black_box(0)),
                    },
                };
                black_box(driver.set_servo(axis, cal)).ok();
            }
            5 => {
                let outcome = frames.apply(&mut driver, &any_action());
                // The outcome to the console port that asked, as
                // `FrameLoop::drain` answers it (any port, any ticket).
                LINK.answer(
                    Asker {
                        port: black_box(0),
                        ticket: black_box(0),
                    },
                    outcome,
                );
                // A console port's action into the queue `drain` reads.
                black_box(COMMANDS.try_submit_from(
                    any_action(),
                    Asker {
                        port: black_box(0),
                        ticket: black_box(0),
                    },
                ))
                .ok();
            }
            6 => {
                // Calibrations the console sent, as `FrameLoop::drain` applies them.
                for (axis, cal) in Axis::ALL.iter().zip(LINK.take_servos()) {
                    if let Some(cal) = cal {
                        black_box(driver.set_servo(*axis, cal)).ok();
                    }
                }
            }
            7 => {
                // The console's parser, on any line of up to 96 bytes.
                let line = black_box([0_u8; 96]);
                let len = usize::from(black_box(0_u8)) % (line.len() + 1);
                black_box(parse(line.get(..len).unwrap_or_default())).ok();
            }
            8 => {
                // The DMX receiver (the UART interrupt's work), any
                // character at any address, DMX on or off.
                let address = DmxAddress::new(black_box(1)).unwrap_or(DmxAddress::FIRST);
                SHOW.dmx.set(DmxSettings {
                    on: black_box(true),
                    address,
                });
                let rx = match black_box(0_u8) {
                    0 => Rx::Break,
                    1 => Rx::Error,
                    byte => Rx::Byte(byte),
                };
                receiver.take(rx, &SHOW.dmx);
                receiver.flush();
            }
            9 => {
                // Bottango's parser on any line of up to 96 bytes, and any
                // motor command on the shared curves.
                let line = black_box([0_u8; 96]);
                let len = usize::from(black_box(0_u8)) % (line.len() + 1);
                black_box(bottango::parse(line.get(..len).unwrap_or_default())).ok();
                let (min, max) = (black_box(0), black_box(0));
                let op = match black_box(0_u8) {
                    0 => Op::Register { min, max },
                    1 => Op::Bounds { min, max },
                    2 => Op::Deregister,
                    3 => Op::Clear,
                    4 => Op::Push(Curve::hold(black_box(0), black_box(0))),
                    _ => Op::Push(any_curve()),
                };
                black_box(SHOW.curves.apply(axis, op)).ok();
                SHOW.curves.set_active(black_box(true));
                if black_box(false) {
                    SHOW.curves.clear_all();
                }
            }
            10 => driver.set_relaxed(black_box(false)),
            11 => {
                // The live settings, calibrations and queued actions, as
                // the frame task takes them before a frame.
                LINK.set_live(any_live());
                let tick = frames.next(black_box(0));
                frames.drain(&mut driver, tick);
            }
            12 => {
                // The inputs' state machine (the input task's, below the
                // frame task) on any levels at any time, with any roles.
                let roles = [0; 4].map(|_| match black_box(0_u8) {
                    0 => InputRole::Off,
                    1 => InputRole::Button(any_action()),
                    _ => InputRole::Presence {
                        toward: black_box(Some(Angle::from_millidegrees(black_box(0)))),
                    },
                });
                let settings = InputSettings {
                    roles,
                    rest_after: RestAfter::seconds(black_box(0)).unwrap_or(RestAfter::Never),
                };
                let now = Micros(black_box(0));
                inputs.configure(&settings, now);
                inputs.update(&settings, now, black_box(0), black_box(false));
                black_box((
                    inputs.pending(&settings),
                    inputs.deadline(&settings),
                    inputs.status(&settings),
                ));
                inputs.sent();
            }
            13 => {
                // The radar's receiver on any bytes, any receive error, and
                // any sighting with any tracking settings for the frame task.
                let bytes = black_box([0_u8; 64]);
                let len = usize::from(black_box(0_u8)) % (bytes.len() + 1);
                idle_head_firmware::radar::feed(
                    &mut radar,
                    bytes.get(..len).unwrap_or_default(),
                    &SHOW.track,
                );
                if black_box(false) {
                    radar.error();
                }
                let mut any = Sighting::NOBODY;
                for slot in &mut any.people {
                    *slot = black_box(Some(Person {
                        x: Millimetres(black_box(0)),
                        y: Millimetres(black_box(0)),
                    }));
                }
                SHOW.track.publish(black_box(Some(any)), radar.counters());
                SHOW.track.set(TrackSettings {
                    radar: black_box(true),
                    gaze: black_box(true),
                    height: Millimetres(black_box(0)),
                    mount: Angle::from_millidegrees(black_box(0)),
                    prefer: if black_box(false) {
                        Prefer::Newest
                    } else {
                        Prefer::Nearest
                    },
                });
                inputs.sense(Micros(black_box(0)), SHOW.track.presence());
                // A new servo rate from the console, taken before a frame.
                let rate = ServoRate::new(black_box(50)).unwrap_or(ServoRate::DEFAULT);
                LINK.set_rate(rate);
                let tick = frames.next(black_box(0));
                frames.take_rate(&mut driver, tick);
            }
            14 => {
                // A telemetry line (`watch`) of the status the last frame
                // published, with any tracker view and any count of lines
                // lost, into a buffer of the line's bound.
                let mut status = LINK.status();
                let mut seen = Sighting::NOBODY;
                for slot in &mut seen.people {
                    *slot = black_box(Some(Person {
                        x: Millimetres(black_box(0)),
                        y: Millimetres(black_box(0)),
                    }));
                }
                status.track = black_box(Some(TrackView {
                    seen,
                    who: black_box(Some(0)),
                    at: black_box(Some(Angle::from_millidegrees(black_box(0)))),
                }));
                let mut out = [0_u8; TELEMETRY_LINE];
                black_box(telemetry_line(&status, black_box(0), &mut out));
            }
            _ => {}
        }
        let tick = frames.next(black_box(0));
        black_box(frames.show(&mut driver, tick));
        let written = frames.write(&mut driver, tick);
        frames.publish(&driver, &written.report);
        black_box((written, driver.is_stopped(), driver.stats()));
    }
}
