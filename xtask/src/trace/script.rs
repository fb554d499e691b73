//! Trace scripts: `<seconds> <command>` a line, the command in the console's
//! words (the core's `console::parse`), or `pin <n> high|low`, or `radar …`
//! (docs/dev/xtask.md, "The trace", has the format).

use anyhow::{Result, bail};
use idle_head_core::behaviour::BehaviourParams;
use idle_head_core::command::{Action, Command};
use idle_head_core::console;

/// One scripted line: its number in the script (from 1), when (µs from the
/// first frame), the command as written, and what it is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Event {
    pub line: usize,
    pub at_us: u64,
    pub text: String,
    pub kind: Kind,
}

/// What a scripted line is: a motion command for the frame task's queue,
/// another console line, an input's level, up to three people (mm) on radar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Act(Action),
    Console,
    Pin { input: u8, high: bool },
    Radar([Option<(i32, i32)>; 3]),
}

/// `text` as seconds (`2`, `2.5`, `0.125`; at most µs), in µs.
pub fn seconds(text: &str) -> Result<u64> {
    let (whole, fraction) = text.split_once('.').unwrap_or((text, "0"));
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !digits(whole) || !digits(fraction) || fraction.len() > 6 {
        bail!("`{text}`: expected seconds such as 2 or 2.5 (at most 6 decimals)");
    }
    let whole: u64 = (whole.parse().ok().filter(|&s| s <= 1_000_000))
        .ok_or_else(|| anyhow::anyhow!("`{text}`: at most 1000000 seconds"))?;
    let micros: u64 = format!("{fraction:0<6}").parse().unwrap_or(0);
    Ok(whole * 1_000_000 + micros)
}

/// `us` as decimal seconds without trailing zeros.
pub fn show_seconds(us: u64) -> String {
    let fraction = format!("{:06}", us % 1_000_000);
    match fraction.trim_end_matches('0') {
        "" => format!("{}", us / 1_000_000),
        digits => format!("{}.{digits}", us / 1_000_000),
    }
}

/// Parses a script: its events, in time order. A script is a program, read
/// top to bottom: a line timed before the line above it is an error (lines
/// at the same time run in line order). Every bad line is reported, each
/// with its number and reason, and then none runs.
pub fn parse(script: &str, params: &BehaviourParams) -> Result<Vec<Event>> {
    let mut events: Vec<Event> = Vec::new();
    let mut errors = Vec::new();
    for (index, raw) in script.lines().enumerate() {
        let line = index + 1;
        let text = raw.split_once('#').map_or(raw, |(before, _)| before).trim();
        if text.is_empty() {
            continue;
        }
        match event(line, text, params) {
            Ok(event) => {
                if let Some(last) = events.last().filter(|last| last.at_us > event.at_us) {
                    errors.push(format!(
                        "line {line}: at {} s, before line {} (at {} s): lines must be in time order",
                        show_seconds(event.at_us),
                        last.line,
                        show_seconds(last.at_us)
                    ));
                    // Later lines are compared with the latest time so far.
                    continue;
                }
                events.push(event);
            }
            Err(reason) => errors.push(format!("line {line}: {reason}")),
        }
    }
    if !errors.is_empty() {
        bail!("{}", errors.join("\n"));
    }
    Ok(events)
}

fn event(line: usize, text: &str, params: &BehaviourParams) -> Result<Event, String> {
    let (time, command) = text
        .split_once(char::is_whitespace)
        .map(|(t, c)| (t, c.trim()))
        .ok_or_else(|| format!("`{text}`: expected `<seconds> <command>`"))?;
    let at_us = seconds(time).map_err(|e| e.to_string())?;
    let (word, rest) = command
        .split_once(char::is_whitespace)
        .unwrap_or((command, ""));
    let rest = rest.trim();
    let kind = match word {
        "pin" if !rest.is_empty() => pin(rest)?,
        "radar" if rest == "none" || rest.contains(',') => radar(rest)?,
        _ => match console::parse(command.as_bytes()) {
            Ok(Command::Act(action)) => {
                params.check(&action).map_err(|e| e.to_string())?;
                Kind::Act(action)
            }
            Ok(_) => Kind::Console,
            Err(e) => return Err(e.describe(command.as_bytes()).to_string()),
        },
    };
    Ok(Event {
        line,
        at_us,
        text: command.to_owned(),
        kind,
    })
}

/// `<n> high|low` (after `pin`).
fn pin(text: &str) -> Result<Kind, String> {
    let usage = || format!("`pin {text}`: expected `pin <2..5> high|low`");
    let (input, level) = text.split_once(char::is_whitespace).ok_or_else(usage)?;
    let input: u8 = input
        .parse()
        .ok()
        .filter(|n| crate::board::PICO_INPUTS.contains(n))
        .ok_or_else(usage)?;
    let high = match level.trim() {
        "high" => true,
        "low" => false,
        _ => return Err(usage()),
    };
    Ok(Kind::Pin { input, high })
}

/// `none` or up to three `<x_mm>,<y_mm>` (after `radar`).
fn radar(text: &str) -> Result<Kind, String> {
    let usage =
        || format!("`radar {text}`: expected `radar none` or `radar <x_mm>,<y_mm>` (up to three)");
    let mut people = [None; 3];
    if text == "none" {
        return Ok(Kind::Radar(people));
    }
    let words: Vec<&str> = text.split_whitespace().collect();
    if words.len() > people.len() {
        return Err(usage());
    }
    let mm = |s: &str| s.parse::<i32>().ok().filter(|v| v.unsigned_abs() <= 32_767);
    for (slot, word) in people.iter_mut().zip(words) {
        let (x, y) = word.split_once(',').ok_or_else(usage)?;
        *slot = Some((mm(x).ok_or_else(usage)?, mm(y).ok_or_else(usage)?));
    }
    Ok(Kind::Radar(people))
}

#[cfg(test)]
mod tests {
    use super::*;
    use idle_head_core::command::{GestureKind, GestureRequest};

    fn params() -> BehaviourParams {
        crate::trace::built_in().unwrap().1
    }

    #[test]
    fn times() {
        assert_eq!(seconds("2").unwrap(), 2_000_000);
        assert_eq!(seconds("2.5").unwrap(), 2_500_000);
        assert_eq!(seconds("0.000001").unwrap(), 1);
        for bad in ["", "-1", "2,5", ".5", "1.", "1.0000001", "x"] {
            assert!(seconds(bad).is_err(), "{bad}");
        }
        assert_eq!(show_seconds(2_500_000), "2.5");
        assert_eq!(show_seconds(3_000_000), "3");
    }

    #[test]
    fn a_script_in_time_order() {
        let script = "\
# a look, a nod, then a shake interrupted by a tilt
1 look 5000 -10000 hold=stay   # first

2.5 nod 6000 900
4 shake
4 tilt -8000
6 center
7 idle amp 50
8 stop
";
        let events = parse(script, &params()).unwrap();
        let lines: Vec<usize> = events.iter().map(|e| e.line).collect();
        let times: Vec<u64> = events.iter().map(|e| e.at_us).collect();
        assert_eq!(lines, [2, 4, 5, 6, 7, 8, 9]);
        let s = 1_000_000;
        assert_eq!(times, [s, 5 * s / 2, 4 * s, 4 * s, 6 * s, 7 * s, 8 * s]);
        let nod = |g: &GestureRequest| g.kind == GestureKind::Nod;
        assert!(matches!(events[1].kind, Kind::Act(Action::Gesture(g)) if nod(&g)));
    }

    #[test]
    fn every_bad_line_is_named_and_nothing_runs() {
        // A line timed before the line above it is one.
        let script = "\
1 nod six
2 wave
3 pin 6 high
x nod
5 nod 30000
6 look 0
7
8 pin 2 up
8.5 nod 6000 900
7 look 5000 -10000
9 shake
8.9 tilt
";
        let err = parse(script, &params()).unwrap_err().to_string();
        assert_eq!(
            err,
            "\
line 1: `six`: amplitude in mdeg must be a whole number
line 2: unknown command `wave` (try `help`)
line 3: `pin 6 high`: expected `pin <2..5> high|low`
line 4: `x`: expected seconds such as 2 or 2.5 (at most 6 decimals)
line 5: nod amplitude 30°: must be in 0.001°..20° (pitch's limits around its neutral pose)
line 6: missing yaw in mdeg
line 7: `7`: expected `<seconds> <command>`
line 8: `pin 2 up`: expected `pin <2..5> high|low`
line 10: at 7 s, before line 9 (at 8.5 s): lines must be in time order
line 12: at 8.9 s, before line 11 (at 9 s): lines must be in time order"
        );
    }
}
