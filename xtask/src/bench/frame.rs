//! The frame rows of the benchmark: instructions of one frame update over
//! a whole loop, idle and with a gesture and a look playing, at 50 Hz and
//! at 333 Hz, each held to its own ceiling; and the CPU load they make,
//! the mean frame's work over the frame period.
//!
//! The load takes one instruction for 1 ns, as QEMU's virtual time under
//! `-icount shift=0` counts it (a Cortex-M0+ at 125 MHz takes about 1.2
//! cycles of 8 ns an instruction: some 10 times that on a Pico).

use anyhow::{Context, Result, bail};

use super::{RP2040_HZ, thousands};
use crate::log::LogLine;

/// A frame row's ceiling, in instructions of one frame update.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ceiling {
    /// The median over the loop.
    pub median: u64,
    pub max: u64,
}

/// The rows the image must report, by scenario, and their ceilings (at
/// every rate). Idle: playback, fade, limits, mapping and PWM writes of
/// three servos, 1,200 at the median (about 10 µs on a 125 MHz RP2040).
/// With a gesture and a look playing, the mixer's gesture shape and the
/// gaze's minimum-jerk moves are evaluated afresh every frame: 2,000 at the
/// median. The costliest frame of either stays within 4,000.
pub const CEILINGS: [(Option<&str>, Ceiling); 2] = [
    (
        None,
        Ceiling {
            median: 1200,
            max: 4000,
        },
    ),
    (
        Some("gesture+look"),
        Ceiling {
            median: 2000,
            max: 4000,
        },
    ),
];

/// The servo rates (Hz) the image must report rows at.
pub const RATES: [u32; 2] = [50, 333];

/// The `frame bench ...` line: instructions per frame update over a loop.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameRow {
    /// The servo rate, Hz (50 in a log without `rate=`).
    pub rate: u32,
    /// What plays besides the idle loops (`gesture+look`), if anything.
    pub scenario: Option<String>,
    pub frames: u64,
    /// Fewest instructions of a frame.
    pub min: u64,
    pub median: u64,
    /// Most instructions of a frame.
    pub max: u64,
    /// The frame that took `max`.
    pub max_at: u64,
    pub mean: u64,
}

impl FrameRow {
    /// Parses a `frame bench frames=... min=... median=... max=... max_at=...
    /// mean=...` message; `None` for any other message, an error for a
    /// malformed one.
    pub fn parse(message: &str) -> Result<Option<Self>> {
        let Some(rest) = message.trim_start().strip_prefix("frame bench ") else {
            return Ok(None);
        };
        let number = |key: &str| -> Result<u64> {
            let value = rest
                .split_whitespace()
                .find_map(|token| token.strip_prefix(key)?.strip_prefix('='))
                .with_context(|| format!("`{message}` has no `{key}=`"))?;
            value
                .parse()
                .with_context(|| format!("`{key}={value}` in `{message}` is not a whole number"))
        };
        let scenario = rest
            .split_whitespace()
            .find_map(|token| token.strip_prefix("scenario="))
            .map(str::to_owned);
        let rate = if rest.contains("rate=") {
            u32::try_from(number("rate")?).context("a rate past u32")?
        } else {
            50
        };
        Ok(Some(Self {
            rate,
            scenario,
            frames: number("frames")?,
            min: number("min")?,
            median: number("median")?,
            max: number("max")?,
            max_at: number("max_at")?,
            mean: number("mean")?,
        }))
    }

    /// The frame rows of a benchmark log (idle, then with a gesture and a
    /// look); fails if one is missing or malformed, or is none of
    /// [`CEILINGS`]' scenarios.
    pub fn all(log: &[LogLine]) -> Result<Vec<Self>> {
        let rows: Vec<Self> = log
            .iter()
            .filter_map(|line| FrameRow::parse(&line.message).transpose())
            .collect::<Result<_>>()?;
        for rate in RATES {
            for (scenario, _) in CEILINGS {
                if !rows
                    .iter()
                    .any(|row| row.rate == rate && row.scenario.as_deref() == scenario)
                {
                    bail!(
                        "the benchmark reported no `frame bench rate={rate}{}` line",
                        scenario.map_or(String::new(), |s| format!(" scenario={s}"))
                    );
                }
            }
        }
        if let Some(row) = rows.iter().find(|row| row.ceiling().is_none()) {
            bail!(
                "the benchmark reported a frame row without a ceiling: `{}`",
                row.label()
            );
        }
        Ok(rows)
    }

    /// This row's ceiling, if its scenario has one.
    pub fn ceiling(&self) -> Option<Ceiling> {
        CEILINGS
            .iter()
            .find(|(scenario, _)| *scenario == self.scenario.as_deref())
            .map(|(_, ceiling)| *ceiling)
    }

    /// The median and the max within this row's ceiling (a row without
    /// one is not).
    pub fn within_budget(&self) -> bool {
        self.ceiling()
            .is_some_and(|c| self.median <= c.median && self.max <= c.max)
    }

    /// The row's label: `frame`, or `frame (gesture + look)`; at another
    /// rate than 50 Hz, with it: `frame at 333 Hz`.
    pub fn label(&self) -> String {
        let base = match &self.scenario {
            None => "frame".to_owned(),
            Some(s) => format!("frame ({})", s.replace('+', " + ")),
        };
        if self.rate == 50 {
            base
        } else {
            format!("{base} at {} Hz", self.rate)
        }
    }

    /// The frame period of the row's rate, µs (the servo rate's rounding
    /// to whole µs: 3003 at 333 Hz).
    pub fn period_us(&self) -> u64 {
        let hz = u64::from(self.rate.max(1));
        (1_000_000 + hz / 2) / hz
    }

    /// The share of the CPU the frame update takes at the row's rate, %:
    /// the mean frame's instructions at one 125 MHz cycle each (a lower
    /// bound: some take two or more) over the frame period.
    pub fn load_percent(&self) -> f64 {
        self.mean as f64 / RP2040_HZ * 1e6 / self.period_us() as f64 * 100.0
    }
}

/// The frame rows over their ceilings, each named with its numbers and
/// ceiling; `None` if every row is within its own.
pub fn frames_over_budget(frames: &[FrameRow]) -> Option<String> {
    let over: Vec<String> = frames
        .iter()
        .filter(|frame| !frame.within_budget())
        .map(|frame| {
            let ceiling = frame.ceiling().map_or_else(
                || "no ceiling".to_owned(),
                |c| format!("ceiling {} and {}", thousands(c.median), thousands(c.max)),
            );
            format!(
                "row `{}` takes {} instructions at the median and {} at most ({ceiling})",
                frame.label(),
                thousands(frame.median),
                thousands(frame.max)
            )
        })
        .collect();
    (!over.is_empty()).then(|| format!("frame update over its ceiling: {}", over.join("; ")))
}
