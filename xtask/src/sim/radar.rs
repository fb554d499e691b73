//! The radar stages (an HLK-LD2450 on GP13, `sim/radar.mjs`): see
//! [`RADAR_STAGE`] and [`RADAR_DMX_STAGE`].

use std::fmt::Write as _;
use std::path::Path;
use std::time::Duration;

use anyhow::{Context, Result, anyhow, bail};
use idle_head_core::seed::BoardId;
use idle_head_core::servo::ServoRate;

use super::node::{Chunk, Config, FlashTiming};
use super::pulses::angle;
use super::run::{self, Boot, Report};
use super::script::{self, Board, line};
use super::{WALL, dmx, planted, stream};
use crate::bench::tracking::{self, Walk};
use crate::log::number;
use crate::project::{self, Metadata, PICO};
use crate::trace::{Event, Kind};

pub const RADAR_STAGE: &str = "Pico image in the RP2040 emulator: a radar walk on GP13 is \
     followed within 5° of the bearing, every pulse the host trace's; two boards' unique ids \
     give two idle motions";
pub const RADAR_DMX_STAGE: &str = "Pico image in the RP2040 emulator: DMX512 on GP9 and the \
     radar on GP13 at once: every frame of both counted, none lost; a flash erase loses no radar \
     frame";

/// Two boards' flash unique ids (as a W25Q16JV reports them).
const BOARDS: [u64; 2] = [0xe661_4103_e745_2d2f, 0xe661_4103_e72b_8a21];

/// `--radar FILE`: its radar lines, after `radar on` at 0.
pub fn read(path: &Path) -> Result<Vec<Event>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the radar lines {}", path.display()))?;
    let events = script::parse(&format!("0 radar on\n{text}"))
        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    if let Some(e) = events
        .iter()
        .skip(1)
        .find(|e| !matches!(e.kind, Kind::Radar(_)))
    {
        bail!(
            "{} line {}: `{}` is not a radar line (`<s> radar <x_mm>,<y_mm> ...` or \
             `<s> radar none`; --script plays other lines)",
            path.display(),
            e.line - 1,
            e.text
        );
    }
    Ok(events)
}

/// The yaw of each frame of `boot`, m°, from its pulses.
fn yaw(boot: &Boot) -> Vec<f64> {
    let timing = run::timing();
    let mut yaw = Vec::new();
    for pulse in &boot.servos[2].pulses {
        yaw.resize(pulse.frame, f64::NAN);
        yaw.push(angle(2, f64::from(pulse.counts) * timing.count_ns));
    }
    yaw
}

/// [`RADAR_STAGE`].
pub fn test_radar(root: &Path, metadata: &Metadata) -> Result<()> {
    let mut problems = Vec::new();
    // The walk.
    let time = Duration::from_micros(tracking::WALK_RUN_US);
    let walk = tracking::walk_script();
    let report = script::host(root, metadata, &walk, time, Board::default())?;
    println!("{}", report.verdict());
    problems.extend(report.problems.iter().map(|p| format!("walk: {p}")));
    let boot = report.first()?;
    let walk = Walk::of(&yaw(boot), u64::from(ServoRate::DEFAULT.period().0))?;
    let rms = walk.rms / 1000.0;
    println!(
        "walk: {} radar frames sent; the yaw {} ms behind the bearing, {rms:.2}° RMS and at most \
         {:.2}° from it after the first second",
        boot.radar_frames,
        walk.lag_ms,
        walk.largest / 1000.0
    );
    if rms.is_nan() || rms > 5.0 {
        problems.push(format!("walk: RMS error {rms:.2}°, not within 5°"));
    }
    let turned = boot.says("track: turned to yaw");
    problem_if!(
        problems,
        !turned,
        "walk: the frame task never logged `track: turned to yaw`"
    );
    // Two boards.
    let mut yaws = Vec::new();
    for uid in BOARDS {
        let (found, yaw) = board(root, metadata, uid)?;
        problems.extend(found);
        yaws.push(yaw);
    }
    let frames = yaws[0].iter().zip(&yaws[1]);
    let n = frames.len();
    let differ = frames.filter(|&(a, b)| (a - b).abs() > 30.0).count();
    println!("two boards: yaw differs by more than a count in {differ} of {n} frames");
    let few = differ < n / 2;
    problem_if!(
        problems,
        few,
        "two boards: the yaw differs in only {differ} of {n} frames"
    );
    project::verdict(&problems)
}

/// One board of flash unique id `uid`: its run, checked against the host
/// trace of its seeds, and `seed`'s reply; the problems and its yaw.
fn board(root: &Path, metadata: &Metadata, uid: u64) -> Result<(Vec<String>, Vec<f64>)> {
    let board = Board {
        uid: Some(uid),
        ..Board::default()
    };
    let report = script::host(root, metadata, "3 seed\n", Duration::from_secs(4), board)?;
    let boot = report.first()?;
    let seed = BoardId(uid).seed().context("an id that is no id")?;
    let mut problems = report.problems.clone();
    let (replies, want) = (boot.replies(false), format!("ok seed=board:{seed}"));
    let (verdict, answers) = (report.verdict(), replies.join(" | "));
    println!("board {uid:016x}: {verdict}, `seed` answers `{answers}`");
    if replies != [want.clone()] {
        problems.push(format!("`seed` answered {replies:?}, not `{want}`"));
    }
    if !boot.says(&format!("board id {uid:016x}: seed board:{seed}")) {
        problems.push("the boot did not log its id".to_owned());
    }
    let problems = problems.iter().map(|p| format!("board {uid:016x}: {p}"));
    let problems = problems.collect();
    Ok((problems, yaw(boot)))
}

/// [`RADAR_DMX_STAGE`]: DMX512 and a person walking up, 1 s to 9 s;
/// `dmx` and `radar` asked at 9.2 s.
pub fn test_radar_dmx(root: &Path, metadata: &Metadata) -> Result<()> {
    let to = Duration::from_secs(9);
    let changes = dmx::alternating(Duration::from_secs(1), to)?;
    let mut script = String::from("0 radar on\n");
    for i in 0..30 {
        let (at, y) = (1.0 + f64::from(i) * 0.1, 3000 - 50 * i);
        let _ = writeln!(script, "{at:.1} radar 300,{y}");
    }
    let query = Duration::from_millis(9200);
    let lines = vec![Chunk::new(b"dmx\r\nradar\r\n".to_vec(), query)];
    let radar = (script.as_str(), to);
    let report = with_radar(root, metadata, radar, lines, query, |config| {
        config.dmx = Some(dmx::line(&changes));
    })?;
    // (The pulses are not the idle's: the radar turns the head. What is
    // checked is that no frame was late: the log says so.)
    let boot = report.first()?;
    let mut problems = stream::check_dmx(boot, changes.len());
    let radar_reply = boot.reply("ok radar=");
    println!("radar: {} frames sent; `{radar_reply}`", boot.radar_frames);
    problems.extend(counted(boot, &radar_reply));
    problems.extend(report.problems.iter().cloned());
    problems.extend(erase(root, metadata)?);
    project::verdict(&problems)
}

/// Runs the shipped image to a second after `query`: the radar lines of `script` to
/// its end, `radar on` at 0.1 s then `lines` on UART0, `setup` the rest.
fn with_radar(
    root: &Path,
    metadata: &Metadata,
    (script, end): (&str, Duration),
    lines: Vec<Chunk>,
    query: Duration,
    setup: impl FnOnce(&mut Config),
) -> Result<Report> {
    let radar = line(&script::parse(script)?, ServoRate::DEFAULT, end);
    let on = Chunk::new(b"radar on\r\n".to_vec(), Duration::from_millis(100));
    let pins = script::pin_script([vec![on], lines].concat());
    let time = query + Duration::from_secs(1);
    super::run_shipped(root, metadata, time, WALL, |config| {
        config.script = Some(pins);
        config.radar = radar;
        setup(config);
    })
}

/// The problem if `reply` missed a frame `boot` sent, or counted one bad.
fn counted(boot: &Boot, reply: &str) -> Option<String> {
    let counter = |name| number(reply, name).ok();
    (counter("frames") != Some(boot.radar_frames) || counter("bad") != Some(0))
        .then(|| format!("radar: `{reply}` for {} frames sent", boot.radar_frames))
}

/// The flash's typical times (W25Q16JV): a sector erase, a page program.
const TYPICAL: FlashTiming = FlashTiming {
    erase: Duration::from_millis(45),
    program: Duration::from_micros(400),
};

/// A `save` at 2 s over noise in the settings sectors (each erase 45 ms
/// with the interrupts off) while a person stands before the radar from
/// 1 s to 5 s; `radar` asked at 5.2 s. The problems.
fn erase(root: &Path, metadata: &Metadata) -> Result<Vec<String>> {
    let sectors = planted::fill(&PICO.elf(metadata), |len| Ok(planted::noise(len)))?;
    let query = Duration::from_millis(5200);
    let lines = vec![
        Chunk::new(b"save\r\n".to_vec(), Duration::from_secs(2)),
        Chunk::new(b"radar\r\n".to_vec(), query),
    ];
    let radar = ("0 radar on\n1 radar -400,1800\n", Duration::from_secs(5));
    let report = with_radar(root, metadata, radar, lines, query, |config| {
        config.rom = Some(TYPICAL);
        config.flash_fill = Some(sectors);
    })?;
    let boot = report.first()?;
    let erased: f64 = boot.flash.iter().filter(|op| op.0).map(|op| op.2).sum();
    let reply = boot.reply("ok radar=");
    println!(
        "save: {:.0} ms of sector erases with the interrupts off; radar: {} frames sent; `{reply}`",
        erased / 1e6,
        boot.radar_frames
    );
    let mut problems: Vec<String> = report.problems.clone();
    if erased < 45e6 {
        problems.push(format!("save: only {:.0} ms of erases", erased / 1e6));
    }
    problems.extend(counted(boot, &reply).map(|p| format!("during a save: {p}")));
    Ok(problems)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn radar_lines_become_the_harness_radar_and_others_do_not() {
        let events = script::parse("0 radar on\n1 nod\n").unwrap();
        assert_eq!(
            line(&events, ServoRate::DEFAULT, Duration::from_secs(2)),
            None
        );
        let events =
            script::parse("0 radar on\n1.5 radar -782,1713 100,2000\n2 radar none\n").unwrap();
        let radar = line(&events, ServoRate::MAX, Duration::from_secs(3)).unwrap();
        assert_eq!(radar["frame_ns"], 3_003_000);
        assert_eq!(radar["lines"][0]["at_ns"], 1_500_000_000_u64);
        assert_eq!(
            radar["lines"][0]["people"],
            json!([[-782, 1713], [100, 2000], null])
        );
        assert_eq!(radar["lines"][1]["people"], json!([null, null, null]));
    }

    #[test]
    fn a_radar_file_holds_radar_lines_only() {
        let dir = tempfile::tempdir().unwrap();
        let (good, bad) = (dir.path().join("good.txt"), dir.path().join("bad.txt"));
        std::fs::write(&good, "1 radar 0,1500\n2 radar none\n").unwrap();
        std::fs::write(&bad, "1 radar 0,1500\n2 nod\n").unwrap();
        let events = read(&good).unwrap();
        assert_eq!(events[0].text, "radar on");
        assert_eq!(events.len(), 3);
        let error = format!("{:#}", read(&bad).unwrap_err());
        assert!(
            error.contains("line 2: `nod` is not a radar line"),
            "{error}"
        );
    }
}
