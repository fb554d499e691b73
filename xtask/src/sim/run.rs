//! One emulator run of a Pico image: the harness's events sorted into boots,
//! the RTT log decoded, every servo's pulses checked against the host.

use std::{path::Path, time::Duration};

use anyhow::{Result, bail};
use idle_head_core::driver::DriverConfig;
use idle_head_core::pwm_clock::{PICO_SYS_HZ, SliceClock};
use idle_head_core::servo::ServoRate;

use super::{
    event::{End, Event, Op, Unmodelled},
    expect,
    image::{self, SERVOS},
    node,
    pulses::{self, Limits, ServoCheck, Timing, Train},
};
use crate::log::{Defmt, LogLine};

/// Wall-time limit of one emulator run.
pub const WALL: Duration = Duration::from_secs(120);

/// No log byte or pin edge for this long: a stuck run (50 frames).
pub const SILENCE: Duration = Duration::from_secs(1);

/// One boot, power-on or a reset to the next reset or the end; times in ns
/// of virtual time since power-on.
#[derive(Debug, Default)]
pub struct Boot {
    pub start: f64,
    pub end: f64,
    /// Whether the watchdog or a power cycle ended it.
    pub watchdog: bool,
    pub power_cycled: bool,
    /// The decoded log, each line with the time its last byte left.
    pub log: Vec<(f64, LogLine)>,
    /// Per servo, what the emulator reported and the verdict on it.
    pub trains: [Train; 3],
    pub servos: [ServoCheck; 3],
    /// Cycles of each frame update; peak stack from the RAM at the end, B.
    pub frame_cycles: Vec<u64>,
    pub stack_peak: Option<u64>,
    /// Bytes UART0 sent; scripted bytes that found its RX FIFO full; when
    /// each UART script's last byte went onto the RX line.
    pub uart: Vec<u8>,
    pub uart_overruns: usize,
    pub uart_lines: Vec<f64>,
    /// When the USB host configured the device; the bytes the device sent;
    /// when each scripted USB chunk went to it.
    pub usb_connected: Option<f64>,
    pub usb: Vec<u8>,
    pub usb_in: Vec<f64>,
    /// The boot ROM's erases (`true`) and programs: bytes, busy ns.
    pub flash: Vec<(bool, u64, f64)>,
    /// When each DMX frame carrying a change ended, and its number.
    pub dmx_changes: Vec<f64>,
    pub dmx_frames: Vec<u64>,
    /// The input pins the script drove: when, which GPIO, high or low.
    pub drives: Vec<(f64, u8, bool)>,
    /// Radar frames sent in the run.
    pub radar_frames: u64,
}

impl Boot {
    /// The reply lines UART0 (`usb`: the USB port) sent, without line ends.
    pub fn replies(&self, usb: bool) -> Vec<String> {
        let bytes = String::from_utf8_lossy(if usb { &self.usb } else { &self.uart });
        bytes.split_terminator("\r\n").map(str::to_owned).collect()
    }

    /// The first reply line on UART0 starting with `start` (none: empty).
    pub fn reply(&self, start: &str) -> String {
        let mut replies = self.replies(false).into_iter();
        replies.find(|r| r.starts_with(start)).unwrap_or_default()
    }

    /// Whether a line of the log contains `text`.
    pub fn says(&self, text: &str) -> bool {
        self.log.iter().any(|(_, line)| line.message.contains(text))
    }
}

/// Everything one run produced.
#[derive(Debug, Default)]
pub struct Report {
    pub boots: Vec<Boot>,
    pub end: End,
    /// The emulator's complaints and how often each came.
    pub emulator: Vec<(String, usize)>,
    pub unmodelled: Vec<Unmodelled>,
    /// What is wrong with the run (it stopped early, a frame is missing...).
    pub problems: Vec<String>,
    /// The servos' rate the pulses were checked at.
    pub rate: ServoRate,
}

/// Runs `elf` for `virtual_time` (at most `wall`) with the harness set up
/// by `setup`, sorted into boots; the pulses not checked.
pub fn run_with(
    root: &Path,
    elf: &Path,
    virtual_time: Duration,
    wall: Duration,
    setup: impl FnOnce(&mut node::Config),
) -> Result<Report> {
    let (image, config) = image::config(elf, "flash.uf2")?;
    let defmt = Defmt::read(elf)?;
    node::ensure(root)?;
    let mut config = node::Config {
        pins: SERVOS.iter().map(|s| s.1).collect(),
        probe: image.frame_update.unwrap_or(0),
        stack: Some(image.stack),
        virtual_time,
        wall,
        silence: SILENCE,
        ..config
    };
    setup(&mut config);
    println!(
        "$ (cd sim && node harness.mjs ...)  # {}, {:.1} s of virtual time",
        crate::project::relative(&config.flash).display(),
        virtual_time.as_secs_f64()
    );
    let mut report = sort(&node::run(root, &config)?, &defmt, image.stack.1)?;
    if image.frame_update.is_none() {
        let problem = "no `FrameLoop::write` symbol: the frame update was inlined";
        report.problems.push(problem.to_owned());
    }
    // An instruction rp2040js does not know runs as a no-op: nothing after
    // it can be trusted.
    for (message, count) in &report.emulator {
        if message.contains("not implemented") {
            let problem = format!("the emulator skipped an instruction ({count}x): {message}");
            report.problems.push(problem);
        }
    }
    report.problems.extend(report.end.problem(SILENCE));
    Ok(report)
}

/// Sorts the events into boots, each log decoded, each peak stack found.
pub fn sort(events: &[Event], defmt: &Defmt, stack_top: u64) -> Result<Report> {
    let mut report = Report::default();
    let mut decoder = None;
    for event in events {
        if let Event::Boot { ns, .. } = event {
            if let Some(last) = report.boots.last_mut() {
                last.end = *ns;
            }
            report.boots.push(Boot {
                start: *ns,
                ..Boot::default()
            });
            decoder = Some(defmt.stream());
            continue;
        }
        let boot = report.boots.last_mut();
        match (event, boot) {
            (Event::Emu { msg, .. }, _) => match report.emulator.iter_mut().find(|(m, _)| m == msg)
            {
                Some((_, count)) => *count += 1,
                None => report.emulator.push((msg.clone(), 1)),
            },
            (Event::Unmodelled(access), _) => report.unmodelled.push(access.clone()),
            (Event::End(_), _) => {}
            (_, None) => bail!("harness event before the first boot: {event:?}"),
            (Event::Rtt { ns, hex }, Some(boot)) => {
                if let Some(decoder) = decoder.as_mut() {
                    let lines = defmt.lines(decoder.as_mut(), &hex.0);
                    boot.log.extend(lines.into_iter().map(|line| (*ns, line)));
                }
            }
            (Event::Stack { low, .. }, Some(boot)) => {
                boot.stack_peak = Some(stack_top.saturating_sub(*low));
            }
            (event, Some(boot)) => into_boot(boot, event),
        }
    }
    report.end = End::of(events)?;
    if let Some(last) = report.boots.last_mut() {
        last.end = report.end.ns;
    }
    Ok(report)
}

/// An event of the current boot into `boot`.
fn into_boot(boot: &mut Boot, event: &Event) {
    let by_pin = |pin| SERVOS.iter().position(|s| s.1 == pin);
    let by_slice = |slice| SERVOS.iter().position(|s| s.2 == slice);
    match *event {
        Event::Edge {
            pin,
            high,
            ns,
            reset: None | Some(false),
        } => {
            if let Some(i) = by_pin(pin) {
                boot.trains[i].edges.push((ns, high));
            }
        }
        Event::Cc { slice, value, ns } => {
            if let Some(i) = by_slice(slice) {
                // Channel A is the low half of the compare register.
                boot.trains[i].writes.push((ns, (value & 0xffff) as u16));
            }
        }
        Event::En {
            slice,
            on: true,
            ns,
        } => {
            if let Some(i) = by_slice(slice) {
                boot.trains[i].enabled.get_or_insert(ns);
            }
        }
        Event::Call { cycles, .. } => boot.frame_cycles.push(cycles),
        Event::Drive { pin, high, ns } => boot.drives.push((ns, pin, high)),
        Event::Watchdog { .. } => boot.watchdog = true,
        Event::Uart { ref hex, .. } => boot.uart.extend(&hex.0),
        Event::Usb { ref hex, .. } => boot.usb.extend(&hex.0),
        Event::UartOverrun { .. } => boot.uart_overruns += 1,
        Event::UartRx { ns, .. } => boot.uart_lines.push(ns),
        Event::UsbConnected { ns } => boot.usb_connected = Some(ns),
        Event::PowerCycle { .. } => boot.power_cycled = true,
        Event::UsbIn { ns, .. } => boot.usb_in.push(ns),
        Event::Dmx { ns, frame, .. } => {
            boot.dmx_changes.push(ns);
            boot.dmx_frames.push(frame);
        }
        Event::Radar { frames, .. } => boot.radar_frames = frames,
        Event::Flash {
            op, len, busy_ns, ..
        } => boot.flash.push((op == Op::Erase, len, busy_ns)),
        _ => {} // a reset's pin release, a slice off: not needed
    }
}

/// Checks every boot's pulses against the shipped image's idle, 50 Hz.
pub fn check(report: &mut Report) -> Result<()> {
    let trains = report.boots.iter().flat_map(|boot| &boot.trains);
    let frames = trains.map(|train| train.writes.len()).max().unwrap_or(0);
    let expected = expect::pico_duties(frames)?;
    check_at(report, &expected, ServoRate::DEFAULT);
    Ok(())
}

/// Checks every boot's pulses against `expected` (the host's
/// `[pitch, roll, yaw]` from frame 0) at `rate`.
pub fn check_at(report: &mut Report, expected: &[[u16; 3]], rate: ServoRate) {
    report.rate = rate;
    let (timing, limits) = (timing_at(rate), limits_at(rate));
    let boots = report.boots.len();
    for (b, boot) in report.boots.iter_mut().enumerate() {
        for (i, train) in boot.trains.iter_mut().enumerate() {
            train.end = boot.end;
            let duties: Vec<u16> = expected.iter().map(|frame| frame[i]).collect();
            let verdict = pulses::check(train, &duties, &timing, limits[i]);
            let name = SERVOS[i].0;
            let prefix = if boots > 1 {
                format!("boot {b}, {name}")
            } else {
                name.to_owned()
            };
            let problems = verdict.problems.iter().map(|p| format!("{prefix}: {p}"));
            report.problems.extend(problems);
            if verdict.held > 0 && !boot.watchdog {
                let held = verdict.held;
                let problem =
                    format!("{prefix}: {held} pulses repeated the last frame: frames stopped");
                report.problems.push(problem);
            }
            boot.servos[i] = verdict;
        }
    }
}

/// The Pico's slice clock at `rate` (`pwm_clock` checks every rate's).
fn clock(rate: ServoRate) -> SliceClock {
    SliceClock::for_period(PICO_SYS_HZ, rate.period()).expect("a slice clock for every rate")
}

/// The PWM timing of the Pico's servo slices at 50 Hz, or at `rate`.
pub fn timing() -> Timing {
    timing_at(ServoRate::DEFAULT)
}

#[allow(clippy::cast_precision_loss)] // 312 500 ps
pub fn timing_at(rate: ServoRate) -> Timing {
    let clock = clock(rate);
    Timing {
        count_ns: clock.count_ps(PICO_SYS_HZ) as f64 / 1e3,
        period_counts: u32::from(clock.top) + 1,
        frame_ns: f64::from(rate.period().0) * 1e3,
    }
}

/// Neutral, shortest and longest pulse of each servo, in counts, at `rate`.
pub fn limits_at(rate: ServoRate) -> [Limits; 3] {
    let mut config = DriverConfig::DEFAULT;
    config.pwm.period = rate.period();
    let (top, pwm) = (clock(rate).top, config.pwm);
    config.servos.map(|servo| Limits {
        neutral: pwm.duty(servo.neutral, top).0,
        min: pwm.duty(servo.min_pulse, top).0,
        max: pwm.duty(servo.max_pulse, top).0,
    })
}

/// The largest `peak stack <n> B` the firmware logged.
pub fn logged_peak_stack<'a>(lines: impl IntoIterator<Item = &'a LogLine>) -> Option<u64> {
    let peak = |line: &LogLine| {
        let (_, rest) = line.message.split_once("peak stack ")?;
        rest.split_whitespace().next()?.parse().ok()
    };
    lines.into_iter().filter_map(peak).max()
}
