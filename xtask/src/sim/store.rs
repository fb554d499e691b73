//! The settings store on the emulated chip, from three starts of the
//! settings sectors (noise, a record of an unknown version, a version 1
//! record): `save` through the boot ROM's flash functions at their worst
//! times, a power cycle, and the next boot on the saved settings
//! (docs/dev/emulators.md, "Settings through a power cycle").
//!
//! What a save does to the head is checked too: lines that arrive on
//! UART0 while the flash is erased (and the interrupts are off) are all
//! answered after it, and the servos, held still meanwhile, go on within
//! the limiter's idle speed and acceleration, no jump.

use std::{fmt::Write as _, path::Path, time::Duration};

use anyhow::{Context, Result, bail};

use super::{
    node::{FlashTiming, UartScript},
    planted,
    run::{self, Boot, FlashOp, Report},
    stages::{WALL, console_ram, shipped_image},
};
use crate::{elf, project::Metadata};

/// Stage name.
pub const STORE_STAGE: &str = "Pico image in the RP2040 emulator: `save` to flash with \
     worst-case erase times, power cycle, the next boot on the saved settings";

/// The datasheet's worst times (W25Q16JV): a sector erase, a page program.
pub const WORST: FlashTiming = FlashTiming {
    erase: Duration::from_millis(400),
    program: Duration::from_millis(3),
};
/// When the script goes out in each boot (after the 2 s fade-in).
const SCRIPT_AT: [Duration; 2] = [Duration::from_secs(3), Duration::from_millis(2_500)];
/// Lines sent while the save erases the flash (boot 0), and when.
const DURING_SAVE: &[u8] = b"servo pitch\r\n";
const DURING_SAVE_LINES: usize = 20;
const DURING_SAVE_AT: Duration = Duration::from_millis(3_030);
/// When the power goes off and on.
const POWER_CYCLE: Duration = Duration::from_secs(5);
/// The whole run: two boots.
const TIME: Duration = Duration::from_millis(8_500);
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

/// A start of the settings sectors.
struct Start {
    what: &'static str,
    sectors: Vec<u8>,
    /// What the first boot must log about them: a level and a text.
    logged: &'static [(&'static str, &'static str)],
    /// The neutral pulses from power-on, µs.
    neutral: [u32; 3],
}

/// The three starts (see the module docs).
fn starts(root: &Path, len: usize) -> Result<[Start; 3]> {
    Ok([
        Start {
            what: "foreign data",
            sectors: noise(len),
            logged: &[("INFO", "settings: defaults (empty store")],
            neutral: [1500; 3],
        },
        Start {
            what: "a record this firmware cannot read",
            sectors: planted::store_of_version::<0>(b"an unknown layout", len)?,
            logged: &[(
                "WARN",
                "settings: defaults; the store at 0x101fc000 holds settings of version 0, not 2",
            )],
            neutral: [1500; 3],
        },
        Start {
            what: "a record of layout version 1",
            sectors: planted::version_1_sectors(root, len)?,
            logged: &[
                ("INFO", "settings: loaded from flash (version 1)"),
                ("INFO", "settings: migrated from version 1 to 2"),
            ],
            neutral: [1520, 1480, 1510],
        },
    ])
}

/// Runs the scenario from every start and checks it (see the module docs).
pub fn test_store(root: &Path, metadata: &Metadata) -> Result<()> {
    let elf_path = shipped_image(root, metadata)?;
    let settings = elf::Image::read(&elf_path)?
        .settings
        .context("the console image has no settings region")?;
    let mut problems = Vec::new();
    for start in starts(root, usize::try_from(settings.end - settings.start)?)? {
        println!("settings sectors holding {}:", start.what);
        let what = start.what;
        let found = run_from(root, &elf_path, settings.start, start)?;
        problems.extend(found.into_iter().map(|p| format!("from {what}: {p}")));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        bail!("{}", problems.join("; "))
    }
}

/// One run with the settings sectors at `at` as `start` has them. Returns
/// the problems found.
fn run_from(root: &Path, elf_path: &Path, at: u64, start: Start) -> Result<Vec<String>> {
    let Start {
        sectors,
        logged,
        neutral,
        ..
    } = start;
    let report = run::run_with(root, elf_path, TIME, WALL, |config| {
        config.rom = Some(WORST);
        config.flash_fill = Some((at, sectors));
        config.power_cycles = vec![POWER_CYCLE];
        config.uart = (0..2)
            .map(|boot| UartScript::new(boot, SCRIPTS[boot].to_vec(), SCRIPT_AT[boot]))
            .chain([UartScript::new(
                0,
                DURING_SAVE.repeat(DURING_SAVE_LINES),
                DURING_SAVE_AT,
            )])
            .collect();
    })?;
    print!("{}", report.log_text(false));
    let mut problems = report.problems.clone();
    let (text, found) = check(&report, logged, neutral);
    print!("{text}");
    problems.extend(found);
    problems.extend(console_ram(elf_path, &report)?);
    Ok(problems)
}

/// The checks of the module docs, for a start whose first boot logs
/// `logged` and runs on `neutral`: a transcript and the problems found.
fn check(report: &Report, logged: &[(&str, &str)], neutral: [u32; 3]) -> (String, Vec<String>) {
    let mut text = String::new();
    let mut problems = Vec::new();
    if report.boots.len() != 2 {
        problems.push(format!(
            "{} boots instead of two (power-on, then the power cycle)",
            report.boots.len()
        ));
        return (text, problems);
    }
    let [first, second] = [&report.boots[0], &report.boots[1]];
    if !first.power_cycled {
        problems.push("the first boot did not end with the power cycle".to_owned());
    }
    for (b, boot) in report.boots.iter().enumerate() {
        if boot.watchdog {
            problems.push(format!("boot {b}: the watchdog reset the board"));
        }
        let _ = writeln!(text, "boot {b}, UART0:");
        let replies = boot.uart_replies();
        let during = if b == 0 { DURING_SAVE_LINES } else { 0 };
        let expected = |i: usize| {
            REPLIES[b].get(i).copied().or_else(|| {
                (i < REPLIES[b].len() + during).then_some(("ok pitch neutral=1520 ", ""))
            })
        };
        for (i, line) in replies.iter().enumerate() {
            let _ = writeln!(text, "  < {line}");
            match expected(i) {
                Some((start, part)) if line.starts_with(start) && line.contains(part) => {}
                Some((start, part)) => problems.push(format!(
                    "boot {b}: reply {i} `{line}` is not `{start}…{part}…`"
                )),
                None => problems.push(format!("boot {b}: an extra reply `{line}`")),
            }
        }
        if replies.len() < REPLIES[b].len() + during {
            problems.push(format!(
                "boot {b}: {} replies, not {}",
                replies.len(),
                REPLIES[b].len() + during
            ));
        }
    }
    for (level, line) in logged {
        if !says_at(first, level, line) {
            problems.push(format!("boot 0 did not log `{level} {line}`"));
        }
    }
    let [pitch, roll, yaw] = neutral;
    let first_neutral = format!("first frame: neutral pulses {pitch} {roll} {yaw} us");
    if !says(first, &first_neutral) {
        problems.push(format!("boot 0 did not log `{first_neutral}`"));
    }
    text.push_str(&flash_summary(&first.flash));
    if !first.flash.iter().any(|op| !op.erase) {
        problems.push("boot 0's save did not program the flash".to_owned());
    }
    let _ = writeln!(
        text,
        "boot 0: longest gap between frames {:.0} ms",
        longest_gap(first) / 1e6
    );
    let (steps, over) = steps_around_the_save(first);
    text.push_str(&steps);
    problems.extend(over);
    if !says(second, "settings: loaded from flash") {
        problems.push("boot 1 did not log the settings loaded from flash".to_owned());
    }
    let saved = [SAVED_PITCH_US, roll, yaw];
    let second_neutral = format!("first frame: neutral pulses {SAVED_PITCH_US} {roll} {yaw} us");
    if !says(second, &second_neutral) {
        problems.push(format!(
            "boot 1 did not log the saved neutral pulses for its first frame (`{second_neutral}`)"
        ));
    }
    let first_us = first_pulses(second);
    let _ = writeln!(text, "boot 1: first pulses {first_us:?} us");
    if first_us != saved.map(Some) {
        problems.push(format!(
            "boot 1's first pulses are {first_us:?} us, not {saved:?} (the saved neutral pulses)"
        ));
    }
    (text, problems)
}

fn says(boot: &Boot, text: &str) -> bool {
    boot.log.iter().any(|(_, line)| line.message.contains(text))
}

/// Whether `boot` logged `text` at `level`.
fn says_at(boot: &Boot, level: &str, text: &str) -> bool {
    boot.log
        .iter()
        .any(|(_, line)| line.level.as_deref() == Some(level) && line.message.contains(text))
}

/// Erases and programs, summed.
fn flash_summary(ops: &[FlashOp]) -> String {
    let sum = |erase: bool| {
        ops.iter()
            .filter(|op| op.erase == erase)
            .fold((0, 0, 0.0), |(n, bytes, ns), op| {
                (n + 1, bytes + op.len, ns + op.busy_ns)
            })
    };
    let ((erases, erase_bytes, erase_ns), (programs, program_bytes, program_ns)) =
        (sum(true), sum(false));
    format!(
        "boot 0, flash: {erases} erases ({erase_bytes} B, busy {:.0} ms), {programs} programs ({program_bytes} B, busy {:.0} ms)\n",
        erase_ns / 1e6,
        program_ns / 1e6
    )
}

/// The longest time between two frames' compare writes of the pitch servo, ns.
/// The largest change of each axis' angle from one pulse to the next, and
/// of that change, from before the save to a second after it: within the
/// limiter's idle speed and acceleration (a frame's worth, and a few counts
/// of rounding), also where the motion goes on after a stall. A summary
/// and the problems.
fn steps_around_the_save(boot: &Boot) -> (String, Vec<String>) {
    let config = idle_head_core::driver::DriverConfig::DEFAULT;
    let frame_s = f64::from(config.frame_period.0) / 1e6;
    let (from, to) = (
        SCRIPT_AT[0].as_secs_f64() - 0.5,
        POWER_CYCLE.as_secs_f64() - 0.2,
    );
    let mut text = String::new();
    let mut problems = Vec::new();
    for (axis, train) in boot.trains.iter().enumerate() {
        let limits = config.motion[axis];
        let count_mdeg = super::count_ns() / f64::from(config.servos[axis].per_degree.0) * 1e3;
        // Each pulse is the angle rounded to a count, and the pulse map's
        // rounding wobbles by a count or two more: a few counts of slack.
        let speed = f64::from(limits.max_speed.0) * 1e3 * frame_s + 2.0 * count_mdeg;
        let accel = f64::from(limits.max_accel.0) * 1e3 * frame_s * frame_s + 5.0 * count_mdeg;
        let angles: Vec<f64> = super::pulses::measure(train)
            .iter()
            .filter(|p| (from * 1e9..to * 1e9).contains(&p.rise))
            .map(|p| super::pulses::angle(axis, p.width))
            .collect();
        let steps: Vec<f64> = angles.windows(2).map(|w| w[1] - w[0]).collect();
        let fastest = steps.iter().fold(0.0_f64, |m, s| m.max(s.abs()));
        // A step of nothing is a pulse repeated: the CPU stalled (a flash
        // write or erase holds the interrupts off) and the servo held where
        // it was. That stop is the stall's; what is checked is how the
        // motion goes on from it.
        let sharpest = steps
            .windows(2)
            .filter(|w| w[1] != 0.0)
            .fold(0.0_f64, |m, w| m.max((w[1] - w[0]).abs()));
        let _ = writeln!(
            text,
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
    (text, problems)
}

fn longest_gap(boot: &Boot) -> f64 {
    boot.trains[0]
        .writes
        .windows(2)
        .map(|pair| pair[1].0 - pair[0].0)
        .fold(0.0, f64::max)
}

/// The width of each servo's first pulse, whole µs.
fn first_pulses(boot: &Boot) -> [Option<u32>; 3] {
    std::array::from_fn(|i| {
        let edges = &boot.trains[i].edges;
        let rise = edges.iter().position(|&(_, high)| high)?;
        let fall = edges.get(rise + 1)?;
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // a pulse: µs
        Some(((fall.0 - edges[rise].0) / 1e3).round() as u32)
    })
}

/// `len` bytes of noise (xorshift32): a store no firmware wrote.
pub(super) fn noise(len: usize) -> Vec<u8> {
    let mut x: u32 = 0x2545_f491;
    (0..len)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x.to_le_bytes()[0]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::LogLine;

    const LOGGED: &[(&str, &str)] = &[("INFO", "settings: defaults (empty store")];
    const NEUTRAL: [u32; 3] = [1500; 3];

    /// Breaks a good report one way.
    type Breaker = fn(&mut Report);

    /// A report of the two boots as a passing run leaves them.
    fn good() -> Report {
        let boot = |log: &[&str], uart: &str, first_us: [f64; 3]| {
            let mut boot = Boot {
                log: log
                    .iter()
                    .map(|m| (0.0, LogLine::new("INFO", *m)))
                    .collect(),
                uart: uart.as_bytes().to_vec(),
                ..Boot::default()
            };
            for (train, us) in boot.trains.iter_mut().zip(first_us) {
                train.edges = vec![(1e6, true), (1e6 + us * 1e3, false)];
            }
            boot
        };
        let mut first = boot(
            &[
                "settings: defaults (empty store at 0x101fc000)",
                "first frame: neutral pulses 1500 1500 1500 us; watchdog armed (100 ms)",
            ],
            &format!(
                "ok\r\nok\r\nok mode=running settings=flash inputs=-,-,-,- seed=board rate=50\r\n{}",
                "ok pitch neutral=1520 per-degree=11111\r\n".repeat(DURING_SAVE_LINES)
            ),
            [1500.0; 3],
        );
        first.power_cycled = true;
        first.flash = vec![FlashOp {
            erase: false,
            addr: 0x101f_c000,
            len: 256,
            busy_ns: 3e6,
            ns: 3e9,
        }];
        let second = boot(
            &[
                "settings: loaded from flash (version 2) at 0x101fc000",
                "first frame: neutral pulses 1520 1500 1500 us; watchdog armed (100 ms)",
            ],
            "ok\r\nok\r\nok pitch neutral=1520 per-degree=11111\r\nok mode=running settings=flash inputs=-,-,-,- seed=board rate=50\r\n",
            [1520.0, 1500.0, 1500.0],
        );
        Report {
            boots: vec![first, second],
            ..Report::default()
        }
    }

    #[test]
    fn a_good_run_passes_and_each_failure_is_named() {
        let (_, problems) = check(&good(), LOGGED, NEUTRAL);
        assert!(problems.is_empty(), "{problems:?}");

        let failing: [(&str, Breaker); 8] = [
            ("the watchdog reset the board", |r| {
                r.boots[0].watchdog = true;
            }),
            (
                "reply 1 `err storage save: settings do not fit the store`",
                |r| {
                    r.boots[0].uart = b"ok\r\nerr storage save: settings do not fit the store\r\nok mode=running settings=changed\r\n".to_vec();
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
            let (_, problems) = check(&report, LOGGED, NEUTRAL);
            assert!(
                problems.iter().any(|p| p.contains(want)),
                "`{want}` not among {problems:?}"
            );
        }
        let (_, problems) = check(&good(), &[("WARN", "holds settings of version 0")], NEUTRAL);
        assert!(
            problems
                .iter()
                .any(|p| p.contains("did not log `WARN holds settings"))
        );
        // Another start's neutral pulses: both boots are checked against them.
        let (_, problems) = check(&good(), LOGGED, [1520, 1480, 1510]);
        assert!(
            problems
                .iter()
                .any(|p| p.contains("boot 0 did not log `first frame: neutral pulses 1520 1480"))
        );
        assert!(
            problems
                .iter()
                .any(|p| p
                    .contains("boot 1's first pulses are [Some(1520), Some(1500), Some(1500)]"))
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
            super::super::pulses::Train {
                enabled: Some(2.6e9),
                edges: edges.collect(),
                ..Default::default()
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
        assert_eq!(steps_around_the_save(&boot).1, Vec::<String>::new());
        // A step of 1.5° out of a standstill: a jump.
        let mut jump = smooth.clone();
        for w in &mut jump[25..] {
            *w += per_mdeg * 1500.0;
        }
        boot.trains[2] = train(&jump);
        let problems = steps_around_the_save(&boot).1;
        assert_eq!(problems.len(), 1, "{problems:?}");
        assert!(problems[0].starts_with("axis 2 jumped around the save"));
    }
}
