//! `cargo xtask sim`: the Pico image, as `cargo run --release` flashes it,
//! in the RP2040 emulator rp2040js (Node.js, `sim/harness.mjs`, which
//! reports raw facts as JSON lines). This module decodes the log, rebuilds
//! the pulse trains and checks them against the host's duties.

mod dmx;
mod event;
mod exchange;
mod expect;
mod flood;
mod harness;
mod image;
mod inputs;
pub mod live;
pub mod node;
mod noise;
mod planted;
pub mod pulses;
mod pulses_csv;
mod run;
mod script;
mod show;
mod stages;
mod store;
mod stream;
mod unmodelled;

use std::{fmt::Write as _, path::PathBuf, time::Duration};

use anyhow::Result;

pub use flood::{FLOOD_STAGE, test_flood};
pub use inputs::{INPUTS_STAGE, test_inputs};
pub use node::folder as node_folder;
pub use script::{default_time as script_time, parse as parse_script};
pub use stream::{
    DMX_STREAM_STAGE, LENGTH as STREAM_LENGTH, UART_STREAM_STAGE, USB_STREAM_STAGE, test_dmx,
    test_stream,
};

/// Plays a script's `events` into the shipped image (built) for `time` from
/// its first frame; every pulse checked against what the firmware wrote:
/// on time, its own frame's, within the servos' limits (see `script.rs`).
pub fn play_script(
    root: &std::path::Path,
    metadata: &crate::project::Metadata,
    events: Vec<crate::trace::Event>,
    time: Duration,
    wall: Duration,
) -> Result<Report> {
    script::play(root, metadata, events, time, wall, script::Against::Written)
}
pub use exchange::BYTE_TIME;
pub use node::UartScript;
pub use noise::{NOISE_STAGE, test_noise};
pub use run::{Boot, Report, logged_peak_stack};
pub use show::{SHOW_STAGE, test_show};

/// The harness's DMX line for a DMX script's text (see `sim/dmx.rs`).
pub fn dmx_line(script: &str) -> Result<serde_json::Value> {
    Ok(dmx::line(&dmx::parse(script)?))
}

/// One PWM count of the servo slices, ns.
pub fn count_ns() -> f64 {
    run::timing().count_ns
}

/// One PWM count of the servo slices at `rate`, ns.
pub fn count_ns_at(rate: idle_head_core::servo::ServoRate) -> f64 {
    run::timing_at(rate).count_ns
}

/// The frame period, ns.
pub fn frame_ns() -> f64 {
    run::timing().frame_ns
}

/// Builds the shipped Pico image and runs it for `time` (at most `wall`),
/// the harness configured by `setup`; the run sorted into boots, its
/// pulses not checked against the host.
pub fn run_shipped(
    root: &std::path::Path,
    metadata: &project::Metadata,
    time: Duration,
    wall: Duration,
    setup: impl FnOnce(&mut node::Config) -> Result<()>,
) -> Result<Report> {
    let elf = stages::shipped_image(root, metadata)?;
    let mut outcome = Ok(());
    let report = run::run_with(root, &elf, time, wall, |config| outcome = setup(config))?;
    outcome.map(|()| report)
}
pub use stages::{
    CONSOLE_STAGE, CONSOLE_TIME, DRILL_STAGE, FAILURES_STAGE, PULSES_STAGE, RATE_STAGE, WALL,
    test_console, test_drill, test_failures, test_pulses, test_rate,
};
pub use store::{STORE_STAGE, test_store};

use crate::project::{self, PICO};
use crate::setup;

/// Options of `cargo xtask sim`.
// The runs are flags that exclude each other (clap checks it).
#[allow(clippy::struct_excessive_bools)]
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Virtual time to run, in seconds (default: 32.5, a 30 s loop, the
    /// 2 s fade-in and half a second of boot; with `--console`, 6).
    #[arg(long = "seconds", value_name = "S", value_parser = virtual_seconds)]
    pub virtual_time: Option<Duration>,
    /// Wall-time limit in seconds.
    #[arg(long, value_name = "S", default_value = "120", value_parser = wall_seconds)]
    pub timeout: Duration,
    /// The watchdog drill instead: build the test image (`--features
    /// watchdog-drill`, in target/watchdog-drill), whose frames stop after
    /// 3 s, and check that the watchdog resets it and the next boot starts
    /// softly again.
    #[arg(long, conflicts_with_all = ["console", "store", "noise", "flood"])]
    pub drill: bool,
    /// The trigger inputs' check instead: a presence script (a sensor on
    /// GP2, a rest after 2 s with relax on, someone at 7 s) played into the
    /// shipped image; the rest, the pulses stopping, the soft wake and the
    /// glance checked from the pulses, every pulse against the host trace.
    #[arg(long, conflicts_with_all = ["drill", "console", "store", "noise", "flood", "script"])]
    pub inputs: bool,
    /// The console instead: a scripted exchange over UART0 and then over
    /// USB CDC-ACM, every reply checked, and the image's RAM with the peak
    /// stack of that run against the budget.
    /// Without `--seconds`, 6 s: both scripts and their replies.
    #[arg(long, conflicts_with_all = ["store", "noise", "flood"])]
    pub console: bool,
    /// The settings store instead: noise, then a record of an unknown
    /// version, then a record of layout version 1 in the settings sectors
    /// at power-on (defaults, defaults, the saved settings migrated);
    /// `servo pitch neutral 1520` and `save` over UART0 with the flash's
    /// worst-case erase times, a power cycle, and the next boot on the saved
    /// settings.
    #[arg(long, conflicts_with_all = ["noise", "flood"])]
    pub store: bool,
    /// Line noise on UART0 instead: a byte received
    /// with a framing error; its line must be answered `err line bytes
    /// lost …`, the next one `ok`.
    #[arg(long, conflicts_with = "flood")]
    pub noise: bool,
    /// A UART flood instead: 200 `status` lines
    /// back to back at 115200 baud, more than the replies keep up with,
    /// then one more line: every line answered once, in order, none lost.
    #[arg(long)]
    pub flood: bool,
    /// A stream instead: a line every 2 ms on UART0 (`uart`) or the USB
    /// serial port (`usb`) for `--seconds` (default 600), every line
    /// answered once, in order, none lost, no frame late.
    #[arg(long, value_name = "PORT", value_parser = ["uart", "usb"], conflicts_with_all = ["flood", "noise", "store", "console", "drill"])]
    pub stream: Option<String>,
    /// List every access to a register the emulator does not model, also
    /// the known gaps that do not matter (summed up in one line without).
    #[arg(long, short)]
    pub verbose: bool,
    /// The show control run instead (the stage of `cargo xtask test`): DMX
    /// frames into GP9 and a Bottango session over USB, each checked from
    /// the pulses on the servo pins (see `xtask/src/sim/show.rs`).
    #[arg(long, conflicts_with_all = ["drill", "console", "store", "noise", "flood", "dmx", "script"])]
    pub show: bool,
    /// Play DMX512 into GP9 (UART1 RX): FILE has lines `<s> <slot>=<value>
    /// …` (slots relative to the head's address, 1-based; values hold until
    /// changed) and `<s> dmx stop`; frames at about 44 Hz with proper
    /// breaks. Runs until 3 s after the last line unless `--seconds`.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["drill", "console", "store", "noise", "flood", "script"])]
    pub dmx: Option<std::path::PathBuf>,
    /// Play a trace script into the shipped image instead (`cargo xtask
    /// trace --script`'s: pin lines drive GP2 to GP5, console lines go to
    /// UART0, times from the first frame) and check every pulse against the
    /// host trace of it. Without `--seconds`, to 5 s after its last line.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["drill", "console", "store", "noise", "flood"])]
    pub script: Option<PathBuf>,
    /// With `--script`: the servos' rate, Hz (50 to 333), from the first
    /// frame: the image boots on settings of that rate (planted in its
    /// settings sectors), and the host trace runs at it.
    #[arg(long, value_name = "HZ", requires = "script", default_value_t = 50,
          value_parser = clap::value_parser!(u16).range(50..=333))]
    pub rate: u16,
    /// With `--script`, `--dmx` or `--show` (or alone: the plain run, the
    /// pulses not checked): write the pulses measured on GP16, GP18 and GP20
    /// to this CSV, one row per frame: `t_ms,pitch_us,roll_us,yaw_us`.
    #[arg(long, value_name = "FILE.csv", conflicts_with_all = ["drill", "console", "store", "noise", "flood"])]
    pub pulses: Option<PathBuf>,
}

/// One loop (30 s), the fade-in (2 s) and half a second for the boot.
pub const DEFAULT_TIME: Duration = Duration::from_millis(32_500);

fn virtual_seconds(value: &str) -> Result<Duration, String> {
    seconds(value, 3600.0)
}

fn wall_seconds(value: &str) -> Result<Duration, String> {
    seconds(value, 86_400.0)
}

fn seconds(value: &str, max: f64) -> Result<Duration, String> {
    let seconds: f64 = value
        .parse()
        .map_err(|_| format!("`{value}`: expected seconds"))?;
    if !(seconds > 0.0 && seconds <= max) {
        return Err(format!("must be above 0 and at most {max} s"));
    }
    Ok(Duration::from_secs_f64(seconds))
}

/// A run of its own that `cargo xtask test` runs as a stage.
type Stage = fn(&std::path::Path, &project::Metadata) -> Result<()>;

/// Whether the run called `what` passed; if not, says why.
fn passed(what: &str, result: Result<()>) -> bool {
    match result {
        Ok(()) => true,
        Err(error) => {
            println!("{what} FAILED: {error:#}");
            false
        }
    }
}

/// `cargo xtask sim`. `Ok(false)` when a check failed.
pub fn command(args: &Args) -> Result<bool> {
    let root = project::root();
    setup::ensure_toolchain(&root)?;
    let metadata = project::metadata(&root)?;
    if let Some(path) = &args.script {
        let rate = idle_head_core::servo::ServoRate::new(args.rate)
            .ok_or_else(|| anyhow::anyhow!("{} Hz: not a servo rate", args.rate))?;
        return script::command(
            &root,
            &metadata,
            path,
            (args.virtual_time, args.timeout),
            rate,
            args.pulses.as_ref(),
        );
    }
    let runs: [(bool, &str, Stage); 5] = [
        (args.inputs, "inputs", inputs::test_inputs),
        (args.drill, "watchdog drill", stages::test_drill),
        (args.flood, "UART flood", flood::test_flood),
        (args.noise, "UART noise", noise::test_noise),
        (args.store, "settings store", store::test_store),
    ];
    if let Some(port) = &args.stream {
        PICO.build(&root)?;
        let port = if port == "usb" { "usb" } else { "uart" };
        let length = args.virtual_time.unwrap_or(stream::LENGTH);
        return Ok(passed(
            "stream",
            stream::test_stream(&root, &metadata, port, length),
        ));
    }
    if let Some((_, what, stage)) = runs.iter().find(|run| run.0) {
        PICO.build(&root)?;
        return Ok(passed(what, stage(&root, &metadata)));
    }
    if args.console {
        let time = args.virtual_time.unwrap_or(CONSOLE_TIME);
        if time < exchange::USB_START + Duration::from_secs(1) {
            println!(
                "console: the USB script starts at {} s; run at least {} s",
                exchange::USB_START.as_secs(),
                exchange::USB_START.as_secs() + 1
            );
            return Ok(false);
        }
        return Ok(passed(
            "console",
            stages::test_console(&root, &metadata, time, args.timeout),
        ));
    }
    if args.show {
        return Ok(passed(
            "show control",
            show::show(&root, &metadata, args.pulses.as_deref()),
        ));
    }
    if args.dmx.is_some() || args.pulses.is_some() {
        return show::command(&root, &metadata, args);
    }
    PICO.build(&root)?;
    let report = run::simulate(
        &root,
        &PICO.elf(&metadata),
        args.virtual_time.unwrap_or(DEFAULT_TIME),
        args.timeout,
        false,
    )?;
    print!("{}", report.log_text(args.verbose));
    print!("{}", report.table());
    println!("{}", report.verdict());
    println!("{}", report.summary());
    Ok(report.problems.is_empty())
}

impl Report {
    /// Frames that went out as their own pulse, on every servo, all boots.
    pub fn frames(&self) -> usize {
        self.boots
            .iter()
            .map(|boot| boot.servos.iter().map(|s| s.fresh).min().unwrap_or(0))
            .sum()
    }

    /// Watchdog resets during the run.
    pub fn watchdog_resets(&self) -> usize {
        self.boots.iter().filter(|boot| boot.watchdog).count()
    }

    /// The peak stack: the larger of what the firmware logged and what the
    /// emulated RAM shows at the end of each boot.
    pub fn peak_stack(&self) -> Option<u64> {
        let logged = self
            .boots
            .iter()
            .filter_map(|boot| run::logged_peak_stack(boot.log.iter().map(|(_, line)| line)));
        let ram = self.boots.iter().filter_map(|boot| boot.stack_peak);
        logged.chain(ram).max()
    }

    /// The decoded log with virtual times, boots and resets marked, and
    /// what the emulator said (`verbose`: each access to a register it does
    /// not model, also the known ones).
    pub fn log_text(&self, verbose: bool) -> String {
        let mut text = String::new();
        for (b, boot) in self.boots.iter().enumerate() {
            let how = match b.checked_sub(1).map(|last| &self.boots[last]) {
                None => "power-on",
                Some(last) if last.power_cycled => "after a power cycle",
                Some(_) => "after a watchdog reset",
            };
            let _ = writeln!(text, "[boot {b} at {:.6} s, {how}]", boot.start / 1e9);
            for (ns, line) in &boot.log {
                let _ = writeln!(text, "{:>11.6} {}", ns / 1e9, line.snapshot());
                if line.is_problem()
                    && let Some(location) = &line.location
                {
                    let _ = writeln!(text, "            └─ {location}");
                }
            }
            if boot.watchdog {
                let _ = writeln!(text, "[watchdog reset at {:.6} s]", boot.end / 1e9);
            }
        }
        for (message, count) in &self.emulator {
            let _ = writeln!(text, "emulator: {message} ({count}x)");
        }
        text.push_str(&unmodelled::lines(&self.unmodelled, verbose));
        text
    }

    /// Per boot and servo: pulses, frames, widths, periods; then the frame
    /// update's cycles and the stack.
    pub fn table(&self) -> String {
        let timing = run::timing_at(self.rate);
        let us = |counts: u32| f64::from(counts) * timing.count_ns / 1e3;
        let mut text = String::new();
        for (b, boot) in self.boots.iter().enumerate() {
            let _ = writeln!(
                text,
                "\nboot {b}, {:.3} s to {:.3} s:\n  {:<6} {:<5} {:>7} {:>7} {:>5} {:>9} {:>9} {:>9}  {:<21} {:>10}",
                boot.start / 1e9,
                boot.end / 1e9,
                "servo",
                "pin",
                "pulses",
                "frames",
                "held",
                "first µs",
                "min µs",
                "max µs",
                "period ns",
                "mismatches"
            );
            for ((name, pin, _), check) in harness::SERVOS.iter().zip(&boot.servos) {
                let widths = check.pulses.iter().map(|p| p.counts);
                let first = check.pulses.first().map_or(0, |p| p.counts);
                let period = check
                    .periods
                    .map_or("-".to_owned(), |(low, high)| format!("{low:.0}..{high:.0}"));
                let _ = writeln!(
                    text,
                    "  {name:<6} GP{pin:<3} {:>7} {:>7} {:>5} {:>9.1} {:>9.1} {:>9.1}  {period:<21} {:>10}",
                    check.pulses.len(),
                    check.fresh,
                    check.held,
                    us(first),
                    us(widths.clone().min().unwrap_or(0)),
                    us(widths.max().unwrap_or(0)),
                    check.mismatches
                );
            }
        }
        let _ = writeln!(text, "\n{}", self.frame_cycles());
        let logged = self
            .boots
            .iter()
            .filter_map(|boot| run::logged_peak_stack(boot.log.iter().map(|(_, line)| line)))
            .max();
        let ram = self.boots.iter().filter_map(|boot| boot.stack_peak).max();
        let bytes = |b: Option<u64>| b.map_or("-".to_owned(), |b| format!("{b} B"));
        let _ = writeln!(
            text,
            "peak stack: {} as the firmware logged it, {} in the emulated RAM at the end",
            bytes(logged),
            bytes(ram)
        );
        let _ = writeln!(
            text,
            "run: {:.3} s of virtual time, {} instructions, {:.1} s of wall time",
            self.end.ns / 1e9,
            self.end.instructions,
            Duration::from_millis(self.end.wall_ms).as_secs_f64()
        );
        text
    }

    /// `frame update: ...` with min, median and max cycles.
    pub fn frame_cycles(&self) -> String {
        // Each boot's first call is the start frame (neutral pulses only).
        let starts: Vec<u64> = self
            .boots
            .iter()
            .filter_map(|b| b.frame_cycles.first().copied())
            .collect();
        let mut cycles: Vec<u64> = self
            .boots
            .iter()
            .flat_map(|b| b.frame_cycles.iter().skip(1).copied())
            .collect();
        cycles.sort_unstable();
        match (cycles.first(), cycles.last()) {
            (Some(min), Some(max)) => format!(
                "frame update (FrameLoop::write), RP2040 cycles as rp2040js counts them: min {min}, \
                 median {}, max {max} over {} frames (start frame {})",
                cycles[cycles.len() / 2],
                cycles.len(),
                starts.first().copied().unwrap_or(0)
            ),
            _ => "frame update: no call seen".to_owned(),
        }
    }

    /// `sim: ok ...` or the problems.
    pub fn verdict(&self) -> String {
        if self.problems.is_empty() {
            format!(
                "sim: ok: {} frames, every pulse the host's duty within one count, periods within one count",
                self.frames()
            )
        } else {
            let mut text = format!("sim: FAILED ({} problems):", self.problems.len());
            for problem in &self.problems {
                let _ = write!(text, "\n  {problem}");
            }
            text
        }
    }

    /// The closing `sim summary ...` line.
    pub fn summary(&self) -> String {
        let timing = run::timing_at(self.rate);
        let pulses: usize = self
            .boots
            .iter()
            .flat_map(|b| &b.servos)
            .map(|s| s.pulses.len())
            .sum();
        let mismatches: usize = self
            .boots
            .iter()
            .flat_map(|b| &b.servos)
            .map(|s| s.mismatches)
            .sum();
        let periods = self
            .boots
            .iter()
            .flat_map(|b| &b.servos)
            .filter_map(|s| s.periods);
        let (low, high) = periods.fold((f64::INFINITY, 0.0_f64), |(l, h), (a, b)| {
            (l.min(a), h.max(b))
        });
        let period = if low.is_finite() {
            format!("{low:.0}..{high:.0}")
        } else {
            "-".to_owned()
        };
        let first: Vec<String> = self.boots.first().map_or_else(Vec::new, |boot| {
            boot.servos
                .iter()
                .map(|s| {
                    s.pulses.first().map_or("-".to_owned(), |p| {
                        format!("{:.0}", f64::from(p.counts) * timing.count_ns / 1e3)
                    })
                })
                .collect()
        });
        format!(
            "sim summary frames={} pulses={pulses} mismatches={mismatches} period_ns={period} first_us={} watchdog_resets={}",
            self.frames(),
            first.join(","),
            self.watchdog_resets()
        )
    }
}
