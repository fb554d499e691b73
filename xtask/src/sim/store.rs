//! The settings store from three starts (noise, an unknown version, a
//! version 1 record): [`STORE_STAGE`], with the lines sent during the erase
//! answered after it and no jump of the servos (docs/dev/emulators.md).

use std::{path::Path, time::Duration};

use anyhow::Result;

use super::{
    node::{FlashTiming, UartScript},
    planted,
    pulses::{angle, measure, spans},
    run::{self, Boot, Report},
    stages::{WALL, console_ram},
};
use crate::log::LogLine;
use crate::project::{self, Metadata, PICO};

pub const STORE_STAGE: &str = "Pico image in the RP2040 emulator: `save` to flash with \
     worst-case erase times, power cycle, the next boot on the saved settings";

/// The datasheet's worst times (W25Q16JV): a sector erase, a page program.
pub const WORST: FlashTiming = FlashTiming {
    erase: Duration::from_millis(400),
    program: Duration::from_millis(3),
};
/// When the script goes out in each boot (after the 2 s fade-in).
const SCRIPT_AT: [Duration; 2] = [Duration::from_secs(3), Duration::from_millis(2_500)];
/// Lines sent while the save erases the flash (boot 0), from 3.03 s.
const DURING_SAVE_LINES: usize = 20;
/// When the power goes off and on.
const POWER_CYCLE: Duration = Duration::from_secs(5);
/// The script of each boot.
const SCRIPTS: [&[u8]; 2] = [
    b"servo pitch neutral 1520\r\nsave\r\nstatus\r\n",
    b"servo pitch neutral 1540\r\nload\r\nservo pitch\r\nstatus\r\n",
];
/// What each reply must start with and hold, in order, per boot.
const REPLIES: [&[(&str, &str)]; 2] = [
    &[
        ("ok", ""),
        ("ok", ""),
        ("ok mode=", " settings=flash inputs=-,-,-,- seed="),
    ],
    &[
        ("ok", ""),
        ("ok", ""),
        ("ok pitch neutral=1520 ", ""),
        ("ok mode=", " settings=flash inputs=-,-,-,- seed="),
    ],
];
/// The neutral pulse the script saves on pitch.
const SAVED_PITCH_US: u32 = 1520;

/// What a first boot logs about a record of an unknown version.
const UNKNOWN: &str =
    "settings: defaults; the store at 0x101fc000 holds settings of version 0, not 2";

/// Runs the scenario from every start and checks it (see the module docs).
pub fn test_store(root: &Path, metadata: &Metadata) -> Result<()> {
    PICO.build(root)?;
    let elf = PICO.elf(metadata);
    // Each start: what the sectors hold, them, what boot 0 logs (level,
    // text), the neutral pulses, µs.
    let starts: [(_, _, &[_], _); 3] = [
        (
            "foreign data",
            planted::fill(&elf, |len| Ok(planted::noise(len)))?,
            &[("INFO", "settings: defaults (empty store")],
            [1500; 3],
        ),
        (
            "a record this firmware cannot read",
            planted::fill(&elf, |len| {
                planted::store_of_version::<0>(b"an unknown layout", len)
            })?,
            &[("WARN", UNKNOWN)],
            [1500; 3],
        ),
        (
            "a record of layout version 1",
            planted::fill(&elf, |len| planted::version_1_sectors(root, len))?,
            &[
                ("INFO", "settings: loaded from flash (version 1)"),
                ("INFO", "settings: migrated from version 1 to 2"),
            ],
            [1520, 1480, 1510],
        ),
    ];
    let mut problems = Vec::new();
    for (what, sectors, logged, neutral) in starts {
        println!("settings sectors holding {what}:");
        let report = run::run_with(root, &elf, Duration::from_millis(8_500), WALL, |config| {
            config.rom = Some(WORST);
            config.flash_fill = Some(sectors);
            config.power_cycles = vec![POWER_CYCLE];
            config.uart = vec![
                UartScript::new(0, SCRIPTS[0], SCRIPT_AT[0]),
                UartScript::new(1, SCRIPTS[1], SCRIPT_AT[1]),
                UartScript::new(
                    0,
                    b"servo pitch\r\n".repeat(DURING_SAVE_LINES),
                    Duration::from_millis(3_030),
                ),
            ];
        })?;
        print!("{}", report.log_text(false));
        let found = check(&report, logged, neutral);
        let found = found.into_iter().chain(report.problems.iter().cloned());
        let found = found.chain(console_ram(metadata, &report)?);
        problems.extend(found.map(|p| format!("from {what}: {p}")));
    }
    project::verdict(&problems)
}

/// The module docs' checks for a start: prints a transcript; the problems.
fn check(report: &Report, logged: &[(&str, &str)], neutral: [u32; 3]) -> Vec<String> {
    let [first, second] = report.boots.as_slice() else {
        let n = report.boots.len();
        return vec![format!(
            "{n} boots instead of two (power-on, then the power cycle)"
        )];
    };
    let mut problems = Vec::new();
    problem_if!(
        problems,
        !first.power_cycled,
        "the first boot did not end with the power cycle"
    );
    for (b, boot) in report.boots.iter().enumerate() {
        problem_if!(
            problems,
            boot.watchdog,
            "boot {b}: the watchdog reset the board"
        );
        println!("boot {b}, UART0:");
        let replies = boot.replies(false);
        // Boot 0: the replies to the lines sent during the save, last.
        let during = if b == 0 { DURING_SAVE_LINES } else { 0 };
        let (count, pitch) = (REPLIES[b].len() + during, ("ok pitch neutral=1520 ", ""));
        let want = |i: usize| REPLIES[b].get(i).copied().or((i < count).then_some(pitch));
        for (i, line) in replies.iter().enumerate() {
            println!("  < {line}");
            match want(i) {
                Some((start, part)) if line.starts_with(start) && line.contains(part) => {}
                Some((start, part)) => problems.push(format!(
                    "boot {b}: reply {i} `{line}` is not `{start}…{part}…`"
                )),
                None => problems.push(format!("boot {b}: an extra reply `{line}`")),
            }
        }
        let n = replies.len();
        problem_if!(problems, n < count, "boot {b}: {n} replies, not {count}");
    }
    for (level, line) in logged {
        let at_level = |l: &LogLine| l.level.as_deref() == Some(level) && l.message.contains(line);
        let logged = first.log.iter().any(|(_, l)| at_level(l));
        problem_if!(problems, !logged, "boot 0 did not log `{level} {line}`");
    }
    let [pitch, roll, yaw] = neutral;
    let first_neutral = format!("first frame: neutral pulses {pitch} {roll} {yaw} us");
    problem_if!(
        problems,
        !first.says(&first_neutral),
        "boot 0 did not log `{first_neutral}`"
    );
    for (erase, what) in [(true, "erases"), (false, "programs")] {
        let ops = first.flash.iter().filter(|op| op.0 == erase);
        let (n, bytes, ns) = ops.fold((0, 0, 0.0), |(n, b, t), op| (n + 1, b + op.1, t + op.2));
        let ms = ns / 1e6;
        println!("boot 0, flash: {n} {what} ({bytes} B, busy {ms:.0} ms)");
    }
    let programmed = first.flash.iter().any(|op| !op.0);
    problem_if!(
        problems,
        !programmed,
        "boot 0's save did not program the flash"
    );
    let gaps = first.trains[0].writes.windows(2).map(|w| w[1].0 - w[0].0);
    println!(
        "boot 0: longest gap between frames {:.0} ms",
        gaps.fold(0.0, f64::max) / 1e6
    );
    problems.extend(steps_around_the_save(first));
    let loaded = second.says("settings: loaded from flash");
    problem_if!(
        problems,
        !loaded,
        "boot 1 did not log the settings loaded from flash"
    );
    let saved = [SAVED_PITCH_US, roll, yaw];
    let second_neutral = format!("first frame: neutral pulses {SAVED_PITCH_US} {roll} {yaw} us");
    problem_if!(
        problems,
        !second.says(&second_neutral),
        "boot 1 did not log the saved neutral pulses for its first frame (`{second_neutral}`)"
    );
    // The width of each servo's first pulse, whole µs.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // a pulse: µs
    let first_us = (second.trains.each_ref()).map(|train| {
        spans(train, 0.0)
            .first()
            .map(|p| (p.width / 1e3).round() as u32)
    });
    println!("boot 1: first pulses {first_us:?} us");
    problem_if!(
        problems,
        first_us != saved.map(Some),
        "boot 1's first pulses are {first_us:?} us, not {saved:?} (the saved neutral pulses)"
    );
    problems
}

/// Each axis' largest step and change of step around the save, within the
/// idle speed and acceleration (and rounding): prints them; the problems.
fn steps_around_the_save(boot: &Boot) -> Vec<String> {
    let config = idle_head_core::driver::DriverConfig::DEFAULT;
    let frame_s = f64::from(config.frame_period.0) / 1e6;
    let from = SCRIPT_AT[0].as_secs_f64() - 0.5;
    let to = POWER_CYCLE.as_secs_f64() - 0.2;
    let mut problems = Vec::new();
    for (axis, train) in boot.trains.iter().enumerate() {
        let limits = config.motion[axis];
        // Each pulse is the angle rounded to a count, and the pulse map's
        // rounding wobbles by a count or two more: a few counts of slack.
        let count = angle(axis, run::timing().count_ns) - angle(axis, 0.0);
        let speed = f64::from(limits.max_speed.0) * 1e3 * frame_s + 2.0 * count;
        let accel = f64::from(limits.max_accel.0) * 1e3 * frame_s * frame_s + 5.0 * count;
        let angles: Vec<f64> = (measure(train).iter())
            .filter(|p| (from * 1e9..to * 1e9).contains(&p.rise))
            .map(|p| angle(axis, p.width))
            .collect();
        let steps: Vec<f64> = angles.windows(2).map(|w| w[1] - w[0]).collect();
        let fastest = steps.iter().fold(0.0_f64, |m, s| m.max(s.abs()));
        // A step of nothing is a pulse repeated: the CPU stalled (a flash
        // write or erase holds the interrupts off) and the servo held where
        // it was. That stop is the stall's; what is checked is how the
        // motion goes on from it.
        let sharpest = (steps.windows(2))
            .filter(|w| w[1] != 0.0)
            .fold(0.0_f64, |m, w| m.max((w[1] - w[0]).abs()));
        println!(
            "boot 0, axis {axis} around the save: steps up to {fastest:.0} m° a frame (limit \
             {speed:.0}), their change up to {sharpest:.0} m° (limit {accel:.0})"
        );
        if fastest > speed || sharpest > accel {
            problems.push(format!(
                "axis {axis} jumped around the save: {fastest:.0} m° in a frame, a change of \
                 {sharpest:.0} m° (limits {speed:.0}, {accel:.0})"
            ));
        }
    }
    problems
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::pulses::Train;

    /// Breaks a good report one way.
    type Breaker = fn(&mut Report);

    const LOGGED: &[(&str, &str)] = &[("INFO", "settings: defaults (empty store")];
    const NEUTRAL: [u32; 3] = [1500; 3];

    /// A boot that logged `log`, answered `uart` and started on `first_us`.
    fn boot(log: &[&str], uart: &str, first_us: [f64; 3]) -> Boot {
        let log = log
            .iter()
            .map(|m| (0.0, LogLine::new("INFO", *m)))
            .collect();
        let mut boot = Boot {
            log,
            uart: uart.as_bytes().to_vec(),
            ..Boot::default()
        };
        for (train, us) in boot.trains.iter_mut().zip(first_us) {
            train.edges = vec![(1e6, true), (1e6 + us * 1e3, false)];
        }
        boot
    }

    /// A report of the two boots as a passing run leaves them.
    fn good() -> Report {
        let status = "ok mode=running settings=flash inputs=-,-,-,- seed=board rate=50\r\n";
        let pitch = "ok pitch neutral=1520 per-degree=11111\r\n";
        let log = [
            "settings: defaults (empty store at 0x101fc000)",
            "first frame: neutral pulses 1500 1500 1500 us; watchdog armed (100 ms)",
        ];
        let uart = format!("ok\r\nok\r\n{status}{}", pitch.repeat(DURING_SAVE_LINES));
        let mut first = boot(&log, &uart, [1500.0; 3]);
        first.power_cycled = true;
        first.flash = vec![(false, 256, 3e6)];
        let log = [
            "settings: loaded from flash (version 2) at 0x101fc000",
            "first frame: neutral pulses 1520 1500 1500 us; watchdog armed (100 ms)",
        ];
        let uart = format!("ok\r\nok\r\n{pitch}{status}");
        let second = boot(&log, &uart, [1520.0, 1500.0, 1500.0]);
        Report {
            boots: vec![first, second],
            ..Report::default()
        }
    }

    #[test]
    fn a_good_run_passes_and_each_failure_is_named() {
        let problems = check(&good(), LOGGED, NEUTRAL);
        assert!(problems.is_empty(), "{problems:?}");
        let failing: [(&str, Breaker); 8] = [
            ("the watchdog reset the board", |r| {
                r.boots[0].watchdog = true;
            }),
            (
                "reply 1 `err storage save: settings do not fit the store`",
                |r| {
                    r.boots[0].uart =
                        b"ok\r\nerr storage save: settings do not fit the store\r\n".to_vec();
                },
            ),
            ("did not program the flash", |r| r.boots[0].flash.clear()),
            ("did not log the settings loaded from flash", |r| {
                r.boots[1].log.remove(0);
            }),
            (
                "first pulses are [Some(1500), Some(1500), Some(1500)]",
                |r| {
                    r.boots[1].trains[0].edges[1].0 = 1e6 + 1.5e6;
                },
            ),
            ("boots instead of two", |r| {
                r.boots.pop();
            }),
            ("boot 0 did not log `INFO settings: defaults", |r| {
                r.boots[0].log[0].1.level = Some("WARN".to_owned());
            }),
            (
                "boot 0 did not log `first frame: neutral pulses 1500 1500 1500 us`",
                |r| {
                    r.boots[0].log.pop();
                },
            ),
        ];
        for (want, break_it) in failing {
            let mut report = good();
            break_it(&mut report);
            let problems = check(&report, LOGGED, NEUTRAL).join("\n");
            assert!(problems.contains(want), "`{want}` not among\n{problems}");
        }
        let problems =
            check(&good(), &[("WARN", "holds settings of version 0")], NEUTRAL).join("\n");
        assert!(problems.contains("did not log `WARN holds settings"));
        // Another start's neutral pulses: both boots are checked against them.
        let problems = check(&good(), LOGGED, [1520, 1480, 1510]).join("\n");
        assert!(problems.contains("boot 0 did not log `first frame: neutral pulses 1520 1480"));
        assert!(
            problems.contains("boot 1's first pulses are [Some(1520), Some(1500), Some(1500)]")
        );
    }

    #[test]
    fn a_jump_around_the_save_is_found_and_a_steady_start_is_not_one() {
        // Pulses every 20 ms from 2.6 s: steady at 1500 µs, then moving
        // off at 0.2° a frame (within 600 °/s²: 0.24° a frame more each).
        let train = |widths: &[f64]| {
            let edges = (0_u32..).zip(widths).flat_map(|(k, us)| {
                let rise = 2.6e9 + 20e6 * f64::from(k);
                [(rise, true), (rise + us * 1e3, false)]
            });
            Train {
                enabled: Some(2.6e9),
                edges: edges.collect(),
                ..Train::default()
            }
        };
        let per_mdeg = 11.111 / 1000.0;
        let smooth: Vec<f64> = (0..40)
            .map(|k| 1500.0 + per_mdeg * 200.0 * f64::from((k - 20).max(0)))
            .collect();
        let mut boot = Boot {
            trains: [train(&smooth), train(&smooth), train(&smooth)],
            ..Boot::default()
        };
        assert_eq!(steps_around_the_save(&boot), Vec::<String>::new());
        // A step of 1.5° out of a standstill: a jump.
        let jump: Vec<f64> = (smooth.iter().enumerate())
            .map(|(k, w)| if k < 25 { *w } else { w + per_mdeg * 1500.0 })
            .collect();
        boot.trains[2] = train(&jump);
        let problems = steps_around_the_save(&boot);
        assert_eq!(problems.len(), 1, "{problems:?}");
        assert!(problems[0].starts_with("axis 2 jumped around the save"));
    }
}
