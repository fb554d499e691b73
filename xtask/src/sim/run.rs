//! One emulator run of a Pico image: the harness's events sorted into boots,
//! the RTT log decoded, every servo's pulses checked against the host.

use std::{fmt::Write as _, path::Path, time::Duration};

use anyhow::{Context, Result, bail};
use defmt_decoder::StreamDecoder;
use idle_head_core::driver::DriverConfig;
use idle_head_core::pwm_clock::{PICO_SYS_HZ, SliceClock};
use idle_head_core::servo::ServoRate;

use super::{
    event::{Event, FlashKind, Why},
    exchange, expect,
    harness::{self, SERVOS},
    node,
    pulses::{self, Limits, ServoCheck, Timing, Train},
    unmodelled::Unmodelled,
};
use crate::log::{Defmt, LogLine};

/// Virtual time without a log byte or a pin edge after which a run is
/// declared stuck: 50 frames.
const SILENCE: Duration = Duration::from_secs(1);

/// One boot: from power-on or a reset to the next reset or the end.
#[derive(Debug, Default)]
pub struct Boot {
    /// When it started and ended, ns of virtual time since power-on.
    pub start: f64,
    pub end: f64,
    /// Whether the watchdog ended it.
    pub watchdog: bool,
    /// The decoded log, each line with the time its last byte left.
    pub log: Vec<(f64, LogLine)>,
    /// Per servo, what the emulator reported.
    pub trains: [Train; 3],
    pub servos: [ServoCheck; 3],
    /// Cycles of each frame update, in order.
    pub frame_cycles: Vec<u64>,
    /// Lowest stack address written, from the emulated RAM at the end.
    pub stack_low: Option<u64>,
    /// Peak stack use, bytes, from `stack_low`.
    pub stack_peak: Option<u64>,
    pub uart: Vec<u8>,
    /// Scripted bytes that found UART0's receive FIFO full.
    pub uart_overruns: usize,
    /// When the last scripted byte went onto the RX line, ns.
    pub uart_sent: Option<f64>,
    /// When each UART script's last byte went onto the RX line, ns.
    pub uart_lines: Vec<f64>,
    /// When the emulator's USB host had configured the device, ns.
    pub usb_connected: Option<f64>,
    /// Bytes the device sent on its CDC-ACM port.
    pub usb: Vec<u8>,
    /// What the boot ROM erased and programmed, in order.
    pub flash: Vec<FlashOp>,
    /// Whether a power cycle ended it.
    pub power_cycled: bool,
    /// When each scripted USB chunk went to the device (a list of chunks).
    pub usb_in: Vec<f64>,
    /// When each DMX frame that carried a change ended, and its number
    /// (from 0).
    pub dmx_changes: Vec<f64>,
    /// See `dmx_changes`.
    pub dmx_frames: Vec<u64>,
    /// The input pins the script drove: when, which GPIO, high or low.
    pub drives: Vec<(f64, u8, bool)>,
    /// The radar frames sent to the end of the run.
    pub radar_frames: u64,
}

impl Boot {
    /// The reply lines UART0 sent, without their line ends.
    pub fn uart_replies(&self) -> Vec<String> {
        String::from_utf8_lossy(&self.uart)
            .split_terminator("\r\n")
            .map(str::to_owned)
            .collect()
    }
}

/// One flash erase or program by the boot ROM.
#[derive(Debug, Clone, PartialEq)]
pub struct FlashOp {
    /// Whether it erased (else programmed).
    pub erase: bool,
    /// Flash address and length, bytes.
    pub addr: u64,
    pub len: u64,
    /// How long it kept the flash busy (and the interrupts off), ns.
    pub busy_ns: f64,
    /// When it ran, ns of virtual time since power-on.
    pub ns: f64,
}

/// How the harness ended.
#[derive(Debug, Default)]
pub struct End {
    /// Why it stopped: [`Why::Time`] when it ran the whole virtual time.
    pub why: Why,
    pub ns: f64,
    pub instructions: u64,
    pub wall_ms: u64,
    /// The harness's error, if it failed.
    pub error: Option<String>,
}

impl End {
    /// Why the run did not reach its virtual time, if it did not.
    pub fn problem(&self, silence: Duration) -> Option<String> {
        let at = self.ns / 1e9;
        match self.why {
            Why::Time => None,
            Why::Silent => Some(format!(
                "the emulator made no progress: no log byte and no pin edge for {} s of virtual \
                 time (stopped at {at:.3} s)",
                silence.as_secs_f64()
            )),
            Why::Asleep => Some(format!(
                "the emulator made no progress: the core sleeps with nothing left to wake it \
                 (at {at:.3} s)"
            )),
            Why::Wall => Some(format!(
                "the emulator made no progress in time: stopped after {:.1} s of wall time at \
                 {at:.3} s of virtual time (raise with --timeout)",
                Duration::from_millis(self.wall_ms).as_secs_f64()
            )),
            Why::Break => Some(format!("the firmware hit a breakpoint at {at:.3} s")),
            Why::Closed => Some(format!("the live run's input closed at {at:.3} s")),
            Why::Error => Some(format!(
                "the emulator stopped (error) at {at:.3} s: {}",
                self.error.as_deref().unwrap_or("no reason given")
            )),
        }
    }
}

/// Everything one run produced.
#[derive(Debug, Default)]
pub struct Report {
    pub boots: Vec<Boot>,
    pub end: End,
    /// The emulator's complaints, each with how often it came.
    pub emulator: Vec<(String, usize)>,
    /// Accesses to peripherals the emulator does not model.
    pub unmodelled: Vec<Unmodelled>,
    /// Problems with the run itself (it stopped early, a frame is missing...).
    pub problems: Vec<String>,
    /// The UART exchange as a transcript, if the run had one.
    pub exchange: Option<String>,
    /// The servos' rate the pulses were checked at (50 Hz unless
    /// [`check_at`] said).
    pub rate: ServoRate,
}

/// Runs `elf` for `virtual_time` (at most `wall` of wall time) and checks
/// it; with `exchange`, also the console exchange over UART0
/// ([`exchange`]).
pub fn simulate(
    root: &Path,
    elf: &Path,
    virtual_time: Duration,
    wall: Duration,
    exchange: bool,
) -> Result<Report> {
    let mut report = run_with(root, elf, virtual_time, wall, |config| {
        if exchange {
            let mut start = exchange::START;
            for line in exchange::script_lines() {
                config.uart.push(node::UartScript::new(0, line, start));
                start += exchange::LINE_GAP;
            }
            config.usb = Some((exchange::script(), exchange::USB_START));
        }
    })?;
    check(&mut report)?;
    if exchange {
        check_exchange(&mut report);
    }
    Ok(report)
}

/// Runs `elf` for `virtual_time` (at most `wall` of wall time) with the
/// harness configured by `setup`, and sorts what happened into boots; the
/// pulses are not checked against the host.
pub fn run_with(
    root: &Path,
    elf: &Path,
    virtual_time: Duration,
    wall: Duration,
    setup: impl FnOnce(&mut node::Config),
) -> Result<Report> {
    let (image, config) = harness::config(elf, "flash.uf2")?;
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
    let events = node::run(root, &config)?;
    let mut report = sort(&events, &defmt)?;
    for boot in &mut report.boots {
        boot.stack_peak = boot.stack_low.map(|low| image.stack.1.saturating_sub(low));
    }
    if image.frame_update.is_none() {
        report
            .problems
            .push("no `FrameLoop::write` symbol: the frame update was inlined".to_owned());
    }
    // An instruction rp2040js does not know runs as a no-op: nothing after
    // it can be trusted.
    for (message, count) in &report.emulator {
        if message.contains("not implemented") {
            report.problems.push(format!(
                "the emulator skipped an instruction ({count}x): {message}"
            ));
        }
    }
    if let Some(problem) = report.end.problem(SILENCE) {
        report.problems.push(problem);
    }
    Ok(report)
}

/// The UART exchange of boot 0 against the host's replies.
fn check_exchange(report: &mut Report) {
    let Some(boot) = report.boots.first() else {
        return;
    };
    let script = exchange::script();
    let [uart_want, usb_want] = exchange::expected(&script);
    let (transcript, problems) = exchange::check(&script, &uart_want, &boot.uart);
    let mut text = format!(
        "UART0 exchange ({} bytes in from {:.1} s at 115200 baud, {} bytes out):\n{transcript}",
        script.len(),
        exchange::START.as_secs_f64(),
        boot.uart.len()
    );
    match boot.uart_sent {
        Some(ns) => {
            let _ = writeln!(text, "  (last byte in at {:.4} s)", ns / 1e9);
        }
        None => report
            .problems
            .push("the harness did not send the whole UART script".to_owned()),
    }
    if boot.uart_overruns > 0 {
        report.problems.push(format!(
            "{} UART bytes found the receive FIFO full (the firmware did not read in time)",
            boot.uart_overruns
        ));
    }
    let (usb, usb_problems) = exchange::check(&script, &usb_want, &boot.usb);
    match boot.usb_connected {
        Some(ns) => {
            let _ = write!(
                text,
                "USB CDC-ACM exchange (enumerated and configured at {:.4} s; {} bytes in at {:.1} s, {} bytes out):\n{usb}",
                ns / 1e9,
                script.len(),
                exchange::USB_START.as_secs_f64(),
                boot.usb.len()
            );
            report
                .problems
                .extend(usb_problems.into_iter().map(|p| format!("USB: {p}")));
        }
        None => report
            .problems
            .push("the emulator's USB host did not configure the device".to_owned()),
    }
    // The script's `center` went through the queue to the frame task, which
    // logs each action it applies with its answer.
    let applied = boot
        .log
        .iter()
        .any(|(_, line)| line.message.contains(": center: ok"));
    if !applied {
        report.problems.push(
            "the frame task did not log the UART's `center` as applied (`frame <n>: center: ok ...`)"
                .to_owned(),
        );
    }
    report
        .problems
        .extend(problems.into_iter().map(|p| format!("UART: {p}")));
    report.exchange = Some(text);
}

/// Sorts the events into boots and decodes each boot's log.
fn sort(events: &[Event], defmt: &Defmt) -> Result<Report> {
    let mut report = Report::default();
    let mut decoder: Option<Box<dyn StreamDecoder + '_>> = None;
    let mut ended = false;
    for event in events {
        match event {
            Event::Boot { ns, .. } => {
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
            Event::Emu { msg, .. } => {
                match report.emulator.iter_mut().find(|(m, _)| m == msg) {
                    Some((_, count)) => *count += 1,
                    None => report.emulator.push((msg.clone(), 1)),
                }
                continue;
            }
            Event::Unmodelled {
                peripheral,
                op,
                offset,
                count,
            } => {
                report.unmodelled.push(Unmodelled {
                    peripheral: peripheral.clone(),
                    op: *op,
                    offset: *offset,
                    count: *count,
                });
                continue;
            }
            Event::End { .. } => {
                report.end = End::from_event(event)?;
                ended = true;
                continue;
            }
            _ => {}
        }
        let Some(boot) = report.boots.last_mut() else {
            bail!("harness event before the first boot: {event:?}");
        };
        if let (Event::Rtt { ns, hex }, Some(decoder)) = (event, decoder.as_mut()) {
            let lines = defmt.lines(decoder.as_mut(), hex);
            boot.log.extend(lines.into_iter().map(|line| (*ns, line)));
        }
        into_boot(boot, event);
    }
    if !ended {
        bail!("the emulator harness ended without saying how");
    }
    if let Some(last) = report.boots.last_mut() {
        last.end = report.end.ns;
    }
    Ok(report)
}

/// An event of the current boot into `boot`; its log bytes through
/// `decoder`.
fn into_boot(boot: &mut Boot, event: &Event) {
    match event {
        Event::Edge {
            pin,
            high,
            ns,
            reset: false,
        } => {
            if let Some(i) = SERVOS.iter().position(|s| s.1 == *pin) {
                boot.trains[i].edges.push((*ns, *high));
            }
        }
        Event::Cc { slice, value, ns } => {
            if let Some(i) = SERVOS.iter().position(|s| s.2 == *slice) {
                // Channel A is the low half of the compare register.
                boot.trains[i].writes.push((*ns, (value & 0xffff) as u16));
            }
        }
        Event::En {
            slice,
            on: true,
            ns,
        } => {
            if let Some(i) = SERVOS.iter().position(|s| s.2 == *slice) {
                let train = &mut boot.trains[i];
                train.enabled = train.enabled.or(Some(*ns));
            }
        }
        Event::Call { cycles, .. } => boot.frame_cycles.push(*cycles),
        Event::Drive { pin, high, ns } => boot.drives.push((*ns, *pin, *high)),
        Event::Watchdog { .. } => boot.watchdog = true,
        Event::Stack { low, .. } => boot.stack_low = Some(*low),
        Event::Uart { hex, .. } => boot.uart.extend(hex),
        Event::Usb { hex, .. } => boot.usb.extend(hex),
        Event::UartOverrun { .. } => boot.uart_overruns += 1,
        Event::UartRx { ns, .. } => {
            boot.uart_sent = Some(*ns);
            boot.uart_lines.push(*ns);
        }
        Event::UsbConnected { ns } => boot.usb_connected = Some(*ns),
        Event::PowerCycle { .. } => boot.power_cycled = true,
        Event::UsbIn { ns, .. } => boot.usb_in.push(*ns),
        Event::Dmx { ns, frame, .. } => {
            boot.dmx_changes.push(*ns);
            boot.dmx_frames.push(*frame);
        }
        Event::Radar { frames, .. } => boot.radar_frames = *frames,
        Event::Flash {
            op,
            addr,
            len,
            busy_ns,
            ns,
        } => boot.flash.push(FlashOp {
            erase: *op == FlashKind::Erase,
            addr: *addr,
            len: *len,
            busy_ns: *busy_ns,
            ns: *ns,
        }),
        // The log is decoded above; a reset's pin release and a slice
        // switched off are not needed; the rest is sorted before a boot is.
        Event::Rtt { .. }
        | Event::Edge { reset: true, .. }
        | Event::En { on: false, .. }
        | Event::Boot { .. }
        | Event::Emu { .. }
        | Event::Unmodelled { .. }
        | Event::End { .. } => {}
    }
}

impl End {
    /// The end of a run from its `end` event.
    fn from_event(event: &Event) -> Result<Self> {
        let Event::End {
            why,
            ns,
            instructions,
            wall_ms,
            msg,
        } = event
        else {
            bail!("not an `end` event: {event:?}");
        };
        Ok(Self {
            why: *why,
            ns: *ns,
            instructions: *instructions,
            wall_ms: *wall_ms,
            error: msg.clone(),
        })
    }
}

/// How a run ended, from its events.
pub fn end_of(events: &[Event]) -> Result<End> {
    let event = events
        .iter()
        .rfind(|event| matches!(event, Event::End { .. }))
        .context("the emulator harness ended without saying how")?;
    End::from_event(event)
}

/// The PWM timing of the Pico's servo slices at 50 Hz.
pub fn timing() -> Timing {
    timing_at(ServoRate::DEFAULT)
}

/// The Pico's slice clock at `rate` (every rate has one:
/// `idle_head_core::pwm_clock` checks it).
fn clock(rate: ServoRate) -> SliceClock {
    SliceClock::for_period(PICO_SYS_HZ, rate.period()).unwrap_or(SliceClock {
        divider_16ths: 0,
        top: 0,
    })
}

/// The PWM timing of the Pico's servo slices at `rate`.
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
    let top = clock(rate).top;
    config.servos.map(|servo| Limits {
        neutral: config.pwm.duty(servo.neutral, top).0,
        min: config.pwm.duty(servo.min_pulse, top).0,
        max: config.pwm.duty(servo.max_pulse, top).0,
    })
}

/// Checks every boot's pulses against the host's duties.
pub fn check(report: &mut Report) -> Result<()> {
    let frames = report
        .boots
        .iter()
        .flat_map(|boot| boot.trains.iter().map(|train| train.writes.len()))
        .max()
        .unwrap_or(0);
    let expected = expect::pico_duties(frames)?;
    check_with(report, &expected);
    Ok(())
}

/// Checks every boot's pulses against `expected`, the duties the host
/// computed for each frame from frame 0 (`[pitch, roll, yaw]`), at 50 Hz.
pub fn check_with(report: &mut Report, expected: &[[u16; 3]]) {
    check_at(report, expected, ServoRate::DEFAULT);
}

/// [`check_with`] for a run at `rate` from its first frame.
pub fn check_at(report: &mut Report, expected: &[[u16; 3]], rate: ServoRate) {
    report.rate = rate;
    let (timing, limits) = (timing_at(rate), limits_at(rate));
    let boots = report.boots.len();
    for (b, boot) in report.boots.iter_mut().enumerate() {
        for (i, train) in boot.trains.iter_mut().enumerate() {
            train.end = boot.end;
            train.reset = boot.watchdog;
            let duties: Vec<u16> = expected.iter().map(|frame| frame[i]).collect();
            let verdict = pulses::check(train, &duties, &timing, limits[i]);
            let name = SERVOS[i].0;
            let prefix = if boots > 1 {
                format!("boot {b}, {name}")
            } else {
                name.to_owned()
            };
            report
                .problems
                .extend(verdict.problems.iter().map(|p| format!("{prefix}: {p}")));
            if verdict.held > 0 && !boot.watchdog {
                report.problems.push(format!(
                    "{prefix}: {} pulses repeated the last frame: frames stopped",
                    verdict.held
                ));
            }
            boot.servos[i] = verdict;
        }
    }
}

/// The largest `peak stack <n> B` the firmware logged.
pub fn logged_peak_stack<'a>(lines: impl IntoIterator<Item = &'a LogLine>) -> Option<u64> {
    lines
        .into_iter()
        .filter_map(|line| {
            let (_, rest) = line.message.split_once("peak stack ")?;
            rest.split_whitespace().next()?.parse().ok()
        })
        .max()
}
