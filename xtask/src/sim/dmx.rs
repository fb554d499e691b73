//! `cargo xtask sim --dmx FILE`: a lighting console on the DMX input (GP9),
//! a line `<seconds> <slot>=<value> …` (from the head's address, 1-based)
//! or `<seconds> dmx stop`.

use std::{fmt::Write as _, path::Path, time::Duration};

use anyhow::{Context, Result, bail};
use serde_json::{Value, json};

use super::node::nanos;

/// The head's address in the image as built (the built-in settings).
pub const ADDRESS: u16 = 1;
/// Slots a frame carries: a full universe.
const SLOTS: u16 = 512;
/// DMX512's break (the console's usual 176 µs; the standard's least is
/// 88 µs), mark after break and byte (11 bits at 250 kbaud).
const BREAK: Duration = Duration::from_micros(176);
const MAB: Duration = Duration::from_micros(12);
const BYTE: Duration = Duration::from_micros(44);
/// Frames back to back, with up to this much more between two.
const JITTER: Duration = Duration::from_millis(1);

/// One line of a DMX script.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Change {
    pub at: Duration,
    /// Slots (relative to the address, 1-based) and their values.
    pub set: Vec<(u16, u8)>,
    /// Whether the frames stop here.
    pub stop: bool,
}

/// Parses a DMX script (see the [module docs](self)).
pub fn parse(text: &str) -> Result<Vec<Change>> {
    let mut changes = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or_default().trim();
        if line.is_empty() {
            continue;
        }
        let here = format!("line {}: `{line}`", n + 1);
        let mut words = line.split_whitespace();
        let seconds: f64 = words
            .next()
            .unwrap_or_default()
            .parse()
            .with_context(|| format!("{here}: the time in seconds first"))?;
        if !(0.0..=3600.0).contains(&seconds) {
            bail!("{here}: the time must be 0 to 3600 s");
        }
        let last = SLOTS - ADDRESS + 1;
        let slot_value = |word: &&str| -> Result<(u16, u8)> {
            let (slot, value) = word
                .split_once('=')
                .with_context(|| format!("{here}: `{word}` is not `<slot>=<value>`"))?;
            let slot = (slot.parse().ok())
                .filter(|s| (1..=last).contains(s))
                .with_context(|| format!("{here}: slot `{slot}` must be 1 to {last}"))?;
            let value = (value.parse())
                .with_context(|| format!("{here}: value `{value}` must be 0 to 255"))?;
            Ok((slot, value))
        };
        let (set, stop) = match words.collect::<Vec<_>>().as_slice() {
            ["dmx", "stop"] => (Vec::new(), true),
            [] => bail!("{here}: nothing to set (`<slot>=<value> ...` or `dmx stop`)"),
            words => (words.iter().map(slot_value).collect::<Result<_>>()?, false),
        };
        let at = Duration::from_secs_f64(seconds);
        changes.push(Change { at, set, stop });
    }
    if changes.is_empty() {
        bail!("no line: a DMX script needs at least one change");
    }
    changes.sort_by_key(|c| c.at);
    Ok(changes)
}

/// Slot 11 (past the head's ten) set to 0 and 100 in turn every 0.23 s
/// from `from` to before `to`.
pub fn alternating(from: Duration, to: Duration) -> Result<Vec<Change>> {
    let (mut text, mut at, mut k) = (String::new(), from, 0);
    while at < to {
        let _ = writeln!(text, "{:.3} 11={}", at.as_secs_f64(), k % 2 * 100);
        (at, k) = (at + Duration::from_millis(230), k + 1);
    }
    parse(&text)
}

/// The harness's `dmx` configuration for `changes`.
pub fn line(changes: &[Change]) -> Value {
    let start = changes.first().map_or(Duration::ZERO, |c| c.at);
    json!({
        "start_ns": nanos(start),
        "period_ns": nanos(BREAK + MAB + BYTE * (u32::from(SLOTS) + 1)),
        "jitter_ns": nanos(JITTER),
        "break_ns": nanos(BREAK),
        "mab_ns": nanos(MAB),
        "byte_ns": nanos(BYTE),
        "slots": SLOTS,
        "address": ADDRESS,
        "changes": changes.iter().map(|c| json!({
            "at_ns": nanos(c.at),
            "set": c.set.iter().map(|&(slot, value)| json!([slot, value])).collect::<Vec<_>>(),
            "stop": c.stop,
        })).collect::<Vec<_>>(),
    })
}

pub fn read(path: &Path) -> Result<Vec<Change>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the DMX script {}", path.display()))?;
    parse(&text).with_context(|| format!("in {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scripts_and_their_mistakes() {
        let changes = parse("# a cue\n3.5 7=255 1=200\n3 9=255\n\n5.0 dmx stop # off\n").unwrap();
        assert_eq!(changes.len(), 3);
        assert_eq!(changes[0].at, Duration::from_secs(3));
        assert_eq!(changes[1].set, [(7, 255), (1, 200)]);
        assert!(changes[2].stop);
        for (bad, says) in [
            ("x 1=2", "line 1"),
            ("1 1=256", "value `256`"),
            ("1 0=1", "slot `0`"),
            ("1 513=1", "slot `513`"),
            ("1 7", "`7` is not"),
            ("1", "nothing to set"),
            ("-1 1=1", "0 to 3600"),
            ("", "no line"),
        ] {
            let error = format!("{:#}", parse(bad).unwrap_err());
            assert!(error.contains(says), "{bad:?}: {error}");
        }
        let config = line(&changes);
        assert_eq!(config["start_ns"], 3_000_000_000_u64);
        assert_eq!(config["changes"][1]["set"][0], json!([7, 255]));
    }
}
