//! `cargo xtask sim`: the shipped Pico image in the RP2040 emulator
//! rp2040js (`sim/harness.mjs` reports raw facts as JSON lines); here the
//! log is decoded and the pulses checked against the host's duties.

/// Pushes `format!(...)` onto `problems` if `cond` holds.
macro_rules! problem_if {
    ($problems:expr, $cond:expr, $($format:tt)+) => {
        if $cond {
            $problems.push(format!($($format)+));
        }
    };
}

pub mod dmx;
mod event;
mod exchange;
mod expect;
mod image;
mod inputs;
pub mod live;
pub mod node;
mod planted;
pub mod pulses;
mod pulses_csv;
mod radar;
pub mod run;
pub mod script;
mod show;
mod stages;
mod store;
mod stream;
mod unmodelled;

use std::{fmt::Write as _, path::Path, path::PathBuf, time::Duration};

use anyhow::{Context, Result, ensure};
use idle_head_core::servo::ServoRate;

pub use inputs::{INPUTS_STAGE, test_inputs};
pub use node::{BYTE_TIME, Chunk, UartScript, folder as node_folder};
pub use run::{Boot, Report, logged_peak_stack};
pub use script::{default_time as script_time, parse as parse_script};
pub use show::{SHOW_STAGE, bottango_lines, test_show};
pub use stages::{
    CONSOLE_STAGE, CONSOLE_TIME, DRILL_STAGE, FAILURES_STAGE, PULSES_STAGE, RATE_STAGE, WALL,
    build_drill, test_console, test_drill, test_failures, test_pulses, test_rate,
};
pub use store::{STORE_STAGE, test_store};
pub use stream::{
    DMX_STREAM_STAGE, FLOOD_STAGE, NOISE_STAGE, TEST_LENGTH as STREAM_LENGTH, UART_STREAM_STAGE,
    USB_STREAM_STAGE, test_dmx, test_flood, test_noise, test_stream,
};

use crate::project::{self, Metadata, PICO};

pub use radar::{RADAR_DMX_STAGE, RADAR_STAGE, test_radar, test_radar_dmx};

/// Builds the shipped Pico image and runs it (see [`run::run_with`]).
pub fn run_shipped(
    root: &Path,
    metadata: &Metadata,
    time: Duration,
    wall: Duration,
    setup: impl FnOnce(&mut node::Config),
) -> Result<Report> {
    PICO.build(root)?;
    run::run_with(root, &PICO.elf(metadata), time, wall, setup)
}

/// Options of `cargo xtask sim`: a plain run or one of group `run`.
#[allow(clippy::struct_excessive_bools)]
#[derive(Debug, Clone, clap::Args)]
#[command(group(clap::ArgGroup::new("run").multiple(false)))]
pub struct Args {
    /// Virtual time to run, in seconds (default 32.5: a loop, the fade-in
    /// and the boot; with `--console`, 6).
    #[arg(long = "seconds", value_name = "S", value_parser = |s: &str| seconds(s, 3600.0))]
    pub virtual_time: Option<Duration>,
    /// Wall-time limit in seconds.
    #[arg(long, value_name = "S", default_value = "120", value_parser = |s: &str| seconds(s, 86_400.0))]
    pub timeout: Duration,
    /// The watchdog drill instead: the test image's frames stop after 3 s;
    /// the watchdog must reset it and the next boot start softly.
    #[arg(long, group = "run")]
    pub drill: bool,
    /// The trigger inputs' check instead: a presence sensor on GP2 rests,
    /// relaxes, wakes softly and glances; every pulse the host trace's.
    #[arg(long, group = "run")]
    pub inputs: bool,
    /// The console instead: a scripted exchange over UART0, then USB, every
    /// reply checked; the image's RAM with the run's peak stack in budget.
    #[arg(long, group = "run")]
    pub console: bool,
    /// The settings store instead: `save` with worst-case erase times, a
    /// power cycle, the next boot on the saved settings.
    #[arg(long, group = "run")]
    pub store: bool,
    /// Line noise on UART0 instead: a line with a framing error must be
    /// answered `err line bytes lost …`, the next one `ok`.
    #[arg(long, group = "run")]
    pub noise: bool,
    /// A UART flood instead: 200 `status` lines back to back, faster than
    /// the replies: every line answered once, in order.
    #[arg(long, group = "run")]
    pub flood: bool,
    /// A stream instead: a line every 2 ms on UART0 or USB for `--seconds`
    /// (default 600): every line answered once, in order, no frame late.
    #[arg(long, value_name = "PORT", value_parser = ["uart", "usb"], group = "run")]
    pub stream: Option<String>,
    /// List every access to a register the emulator does not model, also
    /// the known harmless ones (one line without).
    #[arg(long, short)]
    pub verbose: bool,
    /// The show control stage instead: DMX into GP9 and a Bottango session
    /// over USB, checked from the pulses.
    #[arg(long, group = "run")]
    pub show: bool,
    /// Play DMX512 into GP9: lines `<s> <slot>=<value> …` (slots from the
    /// head's address, 1-based) and `<s> dmx stop`; runs to 3 s after the
    /// last line unless `--seconds`.
    #[arg(long, value_name = "FILE", group = "run")]
    pub dmx: Option<PathBuf>,
    /// Play a trace script (`cargo xtask trace --script`'s) into the image
    /// and check every pulse against its host trace. Without `--seconds`,
    /// to 5 s after its last line.
    #[arg(long, value_name = "FILE", group = "run")]
    pub script: Option<PathBuf>,
    /// Play radar lines (`<s> radar <x_mm>,<y_mm> ...` or `<s> radar none`)
    /// into GP13 as an HLK-LD2450, `radar on` sent first; checked as `--script`.
    #[arg(long, value_name = "FILE", group = "run")]
    pub radar: Option<PathBuf>,
    /// With `--script`: the servos' rate, Hz (50 to 333), planted in the
    /// settings the image boots on; the host trace runs at it too.
    #[arg(long, value_name = "HZ", requires = "script", default_value = "50",
          value_parser = crate::args::servo_rate)]
    pub rate: ServoRate,
    /// With `--script`, `--dmx` or `--show` (alone: a plain run): the pulses
    /// to this CSV, a row per frame: `t_ms,pitch_us,roll_us,yaw_us`.
    #[arg(long, value_name = "FILE.csv",
          conflicts_with_all = ["drill", "inputs", "console", "store", "noise", "flood", "stream"])]
    pub pulses: Option<PathBuf>,
}

/// A loop (30 s), the fade-in (2 s) and half a second of boot.
pub const DEFAULT_TIME: Duration = Duration::from_millis(32_500);

/// Seconds above 0 and at most `max`.
fn seconds(value: &str, max: f64) -> Result<Duration, String> {
    match value.parse::<f64>() {
        Ok(s) if s > 0.0 && s <= max => Ok(Duration::from_secs_f64(s)),
        Ok(_) => Err(format!("must be above 0 and at most {max} s")),
        Err(_) => Err(format!("`{value}`: expected seconds")),
    }
}

/// `cargo xtask sim`. `Ok(false)` when a check failed.
pub fn command(args: &Args) -> Result<bool> {
    let (root, metadata) = crate::setup::prepare()?;
    let (root, md) = (root.as_path(), &metadata);
    PICO.build(root)?;
    if let Some(path) = &args.script {
        return script::command(root, md, script::read(path)?, args);
    }
    if let Some(path) = &args.radar {
        return script::command(root, md, radar::read(path)?, args);
    }
    if args.dmx.is_some() || args.pulses.is_some() && !args.show {
        return show::command(root, md, args);
    }
    let time = args.virtual_time;
    let result = if let Some(port) = &args.stream {
        let port = if port == "usb" { "usb" } else { "uart" };
        stream::test_stream(root, md, port, time.unwrap_or(stream::LENGTH))
    } else if args.console {
        let time = time.unwrap_or(CONSOLE_TIME);
        let least = exchange::USB_START + Duration::from_secs(1);
        ensure!(
            time >= least,
            "console: the USB script starts at {:?}; run at least {least:?}",
            exchange::USB_START
        );
        test_console(root, md, time, args.timeout)
    } else if args.show {
        show::show(root, md, args.pulses.as_deref())
    } else {
        let stages: [(bool, Stage); 5] = [
            (args.inputs, test_inputs),
            (args.drill, test_drill),
            (args.flood, test_flood),
            (args.noise, test_noise),
            (args.store, test_store),
        ];
        if let Some((_, stage)) = stages.iter().find(|run| run.0) {
            stage(root, md)
        } else {
            let time = time.unwrap_or(DEFAULT_TIME);
            let report = stages::checked_run(root, md, time, args.timeout, |_| {})?;
            print!("{}{}", report.log_text(args.verbose), report.table());
            println!("{}\n{}", report.verdict(), report.summary());
            return Ok(report.problems.is_empty());
        }
    };
    Ok(project::passed("sim", &result))
}

/// A run of its own that `cargo xtask test` runs as a stage.
type Stage = fn(&Path, &Metadata) -> Result<()>;

impl Report {
    /// Frames that went out as their own pulse on every servo, all boots.
    pub fn frames(&self) -> usize {
        let fresh = |boot: &Boot| boot.servos.iter().map(|s| s.fresh).min().unwrap_or(0);
        self.boots.iter().map(fresh).sum()
    }

    pub fn watchdog_resets(&self) -> usize {
        self.boots.iter().filter(|boot| boot.watchdog).count()
    }

    /// The first boot, which every run has.
    pub fn first(&self) -> Result<&Boot> {
        self.boots.first().context("no boot")
    }

    /// The larger of the peak stack the firmware logged and the emulated
    /// RAM's at the end of each boot.
    pub fn peak_stack(&self) -> Option<u64> {
        self.logged_stack()
            .max(self.boots.iter().filter_map(|b| b.stack_peak).max())
    }

    fn logged_stack(&self) -> Option<u64> {
        let logged = |boot: &Boot| logged_peak_stack(boot.log.iter().map(|(_, line)| line));
        self.boots.iter().filter_map(logged).max()
    }

    /// Prints the verdict and summary; fails with the run's problems and
    /// the scenario's `more`, if any.
    pub fn conclude(&self, more: impl IntoIterator<Item = String>) -> Result<()> {
        println!("{}\n{}", self.verdict(), self.summary());
        let problems: Vec<String> = self.problems.iter().cloned().chain(more).collect();
        project::verdict(&problems)
    }

    /// The decoded log with virtual times, boots and resets marked, and what
    /// the emulator said (`verbose`: also the known unmodelled registers).
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
                if let (true, Some(location)) = (line.is_problem(), &line.location) {
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
        text + &unmodelled::lines(&self.unmodelled, verbose)
    }

    /// Per boot and servo: pulses, frames, widths, periods; the frame
    /// update's cycles, the stack and the run.
    pub fn table(&self) -> String {
        let us = |counts: u32| f64::from(counts) * run::timing_at(self.rate).count_ns / 1e3;
        let mut text = String::new();
        for (b, boot) in self.boots.iter().enumerate() {
            let (start, end) = (boot.start / 1e9, boot.end / 1e9);
            let _ = writeln!(
                text,
                "\nboot {b}, {start:.3} s to {end:.3} s:\n  servo  pin    pulses  frames  held  first µs    \
                 min µs    max µs  period ns             mismatches"
            );
            for ((name, pin, _), check) in image::SERVOS.iter().zip(&boot.servos) {
                let widths = || check.pulses.iter().map(|p| p.counts);
                let first = check.pulses.first().map_or(0, |p| p.counts);
                let period =
                    (check.periods).map_or("-".to_owned(), |(lo, hi)| format!("{lo:.0}..{hi:.0}"));
                let _ = writeln!(
                    text,
                    "  {name:<6} GP{pin:<3} {:>7} {:>7} {:>5} {:>9.1} {:>9.1} {:>9.1}  {period:<21} {:>10}",
                    check.pulses.len(),
                    check.fresh,
                    check.held,
                    us(first),
                    us(widths().min().unwrap_or(0)),
                    us(widths().max().unwrap_or(0)),
                    check.mismatches
                );
            }
        }
        // Each boot's first call is the start frame (neutral pulses only).
        let start = self.boots.first().and_then(|b| b.frame_cycles.first());
        let cycles = self
            .boots
            .iter()
            .flat_map(|b| b.frame_cycles.iter().skip(1));
        let mut cycles: Vec<u64> = cycles.copied().collect();
        cycles.sort_unstable();
        let _ = match (cycles.first(), cycles.last()) {
            (Some(min), Some(max)) => writeln!(
                text,
                "\nframe update (FrameLoop::write), RP2040 cycles as rp2040js counts them: min {min}, \
                 median {}, max {max} over {} frames (start frame {})",
                cycles[cycles.len() / 2],
                cycles.len(),
                start.unwrap_or(&0),
            ),
            _ => writeln!(text, "\nframe update: no call seen"),
        };
        let bytes = |b: Option<u64>| b.map_or("-".to_owned(), |b| format!("{b} B"));
        let ram = self.boots.iter().filter_map(|boot| boot.stack_peak).max();
        let _ = writeln!(
            text,
            "peak stack: {} as the firmware logged it, {} in the emulated RAM at the end\n\
             run: {:.3} s of virtual time, {} instructions, {:.1} s of wall time",
            bytes(self.logged_stack()),
            bytes(ram),
            self.end.ns / 1e9,
            self.end.instructions,
            Duration::from_millis(self.end.wall_ms).as_secs_f64()
        );
        text
    }

    /// `sim: ok ...` or the problems.
    pub fn verdict(&self) -> String {
        if self.problems.is_empty() {
            return format!(
                "sim: ok: {} frames, every pulse the host's duty within one count, periods within one count",
                self.frames()
            );
        }
        let (n, problems) = (self.problems.len(), self.problems.join("\n  "));
        format!("sim: FAILED ({n} problems):\n  {problems}")
    }

    /// The closing `sim summary ...` line.
    pub fn summary(&self) -> String {
        let servos = || self.boots.iter().flat_map(|b| &b.servos);
        let pulses: usize = servos().map(|s| s.pulses.len()).sum();
        let mismatches: usize = servos().map(|s| s.mismatches).sum();
        let periods = servos().filter_map(|s| s.periods);
        let period = periods.reduce(|(l, h), (a, b)| (l.min(a), h.max(b)));
        let period = period.map_or("-".to_owned(), |(l, h)| format!("{l:.0}..{h:.0}"));
        let count_ns = run::timing_at(self.rate).count_ns;
        let us = |p: &pulses::Pulse| format!("{:.0}", f64::from(p.counts) * count_ns / 1e3);
        let first = self.boots.iter().take(1).flat_map(|b| &b.servos);
        let first: Vec<String> = first
            .map(|s| s.pulses.first().map_or("-".to_owned(), us))
            .collect();
        format!(
            "sim summary frames={} pulses={pulses} mismatches={mismatches} period_ns={period} first_us={} watchdog_resets={}",
            self.frames(),
            first.join(","),
            self.watchdog_resets()
        )
    }
}
