//! `cargo xtask sim --script FILE`: a trace script into the shipped image
//! (pin lines on GP2 to GP5, console lines on UART0, radar lines on GP13;
//! times from the first frame), every pulse against its host trace.

use std::path::Path;
use std::time::Duration;

use anyhow::{Result, bail};
use serde_json::{Value, json};

use idle_head_core::seed::BoardId;
use idle_head_core::servo::ServoRate;
use idle_head_core::settings::Settings;

use super::image::SERVOS;
use super::node::{Chunk, PinLevel, PinScript, nanos};
use super::run::{self, Report};
use super::{planted, pulses_csv};
use crate::project::{Metadata, PICO};
use crate::trace::{self, Event, Kind, radar::PERIOD_US};

/// How much before its time a console line (or a radar frame) is in.
pub const EARLY: Duration = Duration::from_millis(2);

/// The radar's (an LD2450's) line rate.
const BAUD: u32 = 256_000;

/// The console reads its UART some 40 ms after the first frame: an earlier
/// line moves here, in the emulator and the host trace alike.
pub const CONSOLE_UP: Duration = Duration::from_millis(100);

pub fn read(path: &Path) -> Result<Vec<Event>> {
    trace::read_script(path, &trace::built_in()?.1)
}

pub fn parse(text: &str) -> Result<Vec<Event>> {
    trace::parse_script(text, &trace::built_in()?.1)
}

/// How long a script runs when not told: to 5 s after its last line.
pub fn default_time(events: &[Event]) -> Duration {
    let last = events.last().map_or(0, |e| e.at_us);
    Duration::from_micros(last) + Duration::from_secs(5)
}

/// The board a script plays on: the servos' rate (planted in its settings)
/// and the flash's unique id (none: all ones, the paper's seeds).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Board {
    pub rate: ServoRate,
    pub uid: Option<u64>,
}

/// What a script run's pulses are checked against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Against {
    /// The host trace's duties, frame for frame.
    Host,
    /// The duties the firmware wrote: every pulse carries its own frame's
    /// duty, within the servos' limits and on time (for runs whose inputs
    /// land at any phase, where the host's frame and the board's may
    /// differ by one at an edge within microseconds of a frame).
    Written,
}

/// Runs `events` in the shipped image (built) for `time` from its first
/// frame (at most `wall`) on `board`; every pulse checked `against`.
pub fn play(
    root: &Path,
    metadata: &Metadata,
    mut events: Vec<Event>,
    (time, wall): (Duration, Duration),
    against: Against,
    board: Board,
) -> Result<Report> {
    let rate = board.rate;
    if let Some(e) = events.iter().find(|e| changes_rate(&e.text)) {
        bail!(
            "{:.3} s `{}`: the emulator's pulse check runs at one servo rate; give it with \
             --rate (`cargo xtask trace` plays a change of rate)",
            Duration::from_micros(e.at_us).as_secs_f64(),
            e.text
        );
    }
    let period = u64::from(rate.period().0);
    let up = u64::try_from(CONSOLE_UP.as_micros()).unwrap_or(u64::MAX);
    for event in &mut events {
        if !matches!(event.kind, Kind::Pin { .. }) && event.at_us < up {
            event.at_us = up;
        }
    }
    // (Lines keep their order: a pin line before 0.1 s stays first.)
    events.sort_by_key(|e| e.at_us);
    let mut script = pin_script(Vec::new());
    for event in &events {
        let at = Duration::from_micros(event.at_us);
        // A line goes in before the frame that takes it in the host trace.
        let frame = Duration::from_micros(event.at_us.next_multiple_of(period));
        match event.kind {
            Kind::Pin { input: pin, high } => script.pins.push(PinLevel { at, pin, high }),
            Kind::Act(_) | Kind::Console => {
                let line = format!("{}\r\n", event.text);
                script.lines.push(Chunk::new(line, frame));
            }
            Kind::Radar(_) => {} // see `line`
        }
    }
    let radar = line(&events, rate, time);
    let settings = Settings {
        rate,
        ..Settings::DEFAULT
    };
    let sectors = |len| planted::settings_sectors(&settings, len);
    let planted = (rate != ServoRate::DEFAULT).then(|| planted::fill(&PICO.elf(metadata), sectors));
    let planted = planted.transpose()?;
    // The boot before the first frame: well under a tenth of a second.
    let boot = Duration::from_millis(100);
    let mut report = run::run_with(root, &PICO.elf(metadata), time + boot, wall, |config| {
        config.inputs = crate::board::PICO_INPUTS.to_vec();
        config.script = Some(script);
        config.flash_fill = planted;
        config.radar = radar;
        config.uid = board.uid.map(|id| format!("{id:016x}"));
        // A head relaxed at rest is silent for as long as it rests (no
        // pulse, no log line but once a loop): the wall limit alone tells a
        // stuck run.
        config.silence = time + boot;
    })?;
    let expected: Vec<[u16; 3]> = match against {
        Against::Host => {
            // The host's frames outlast the emulator's (which began a
            // little after power-on).
            let seeds = board
                .uid
                .map(|id| Settings::DEFAULT.idle_seeds(BoardId(id)));
            let micros = u64::try_from((time + 2 * boot).as_micros()).unwrap_or(u64::MAX);
            let host = trace::simulate(micros, seeds, rate, &events, None, &[])?;
            host.rows.iter().map(|row| row.duties).collect()
        }
        Against::Written => written(&report),
    };
    run::check_at(&mut report, &expected, rate);
    Ok(report)
}

/// Boot 0's script: `lines` on UART0, [`EARLY`], from the first frame.
pub fn pin_script(lines: Vec<Chunk>) -> PinScript {
    PinScript {
        anchor_slice: SERVOS[0].2,
        lines,
        early: EARLY,
        ..PinScript::default()
    }
}

/// Plays `text` on `board` for `time`, checked against its host trace.
pub fn host(
    root: &Path,
    metadata: &Metadata,
    text: &str,
    time: Duration,
    board: Board,
) -> Result<Report> {
    let time = (time, run::WALL);
    play(root, metadata, parse(text)?, time, Against::Host, board)
}

/// Whether a console line sets the servo rate (`servo rate <hz>`).
fn changes_rate(line: &str) -> bool {
    let line = line.to_ascii_lowercase();
    let words: Vec<&str> = line.split_whitespace().collect();
    matches!(words.as_slice(), ["servo", "rate", _, ..])
}

/// The duties boot 0 wrote, from frame 0 (the write before the enable).
fn written(report: &Report) -> Vec<[u16; 3]> {
    let Some(boot) = report.boots.first() else {
        return Vec::new();
    };
    let frames = boot.trains.each_ref().map(|t| t.frames().unwrap_or(&[]));
    let n = frames.iter().map(|f| f.len()).max().unwrap_or(0);
    let duty = |k: usize| core::array::from_fn(|i| frames[i].get(k).map_or(0, |f| f.1));
    (0..n).map(duty).collect()
}

/// `cargo xtask sim --script FILE` or `--radar FILE`: its `events`.
pub fn command(
    root: &Path,
    metadata: &Metadata,
    events: Vec<Event>,
    args: &super::Args,
) -> Result<bool> {
    let rate = args.rate;
    let time = args.virtual_time.unwrap_or_else(|| default_time(&events));
    let board = Board { rate, uid: None };
    let wall = args.timeout;
    let report = play(root, metadata, events, (time, wall), Against::Host, board)?;
    print!("{}", report.log_text(false));
    let boot = report.first()?;
    println!("UART0 replies:");
    for reply in boot.replies(false) {
        println!("  < {reply}");
    }
    print!("{}", report.table());
    let verdict = report
        .verdict()
        .replace("the host's duty", "the host trace's duty");
    println!("{verdict}\n{}", report.summary());
    if let Some(path) = &args.pulses {
        pulses_csv::write(path, &boot.trains, &run::timing_at(rate))?;
    }
    Ok(report.problems.is_empty())
}

/// The harness's `radar` for the radar lines of `events` (none: none
/// wired), to `time`, each line in [`EARLY`] before its frame at `rate`.
pub fn line(events: &[Event], rate: ServoRate, time: Duration) -> Option<Value> {
    let lines: Vec<Value> = events
        .iter()
        .filter_map(|e| match e.kind {
            Kind::Radar(people) => Some(json!({
                "at_ns": e.at_us * 1000,
                "people": people.map(|p| p.map(|(x, y)| [x, y])),
            })),
            _ => None,
        })
        .collect();
    (!lines.is_empty()).then(|| {
        json!({
            "baud": BAUD,
            "period_ns": PERIOD_US * 1000,
            "frame_ns": u64::from(rate.period().0) * 1000,
            "early_ns": nanos(EARLY),
            "end_ns": nanos(time),
            "lines": lines,
        })
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_rate_change_is_told_from_a_rate_query() {
        assert!(super::changes_rate("servo rate 333"));
        assert!(super::changes_rate("SERVO  Rate 60"));
        assert!(!super::changes_rate("servo rate"));
        assert!(!super::changes_rate("servo yaw neutral 1500"));
    }
}
