//! The events `sim/harness.mjs` prints, a JSON object a line tagged by
//! `ev`. An unknown event or field, or one missing, is an error: the
//! harness and its reader change together.

use anyhow::{Context, Result};
use serde::Deserialize;
use std::time::Duration;

/// One event of the harness. Times (`ns`) are virtual nanoseconds since
/// power-on, across resets.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "ev", rename_all = "snake_case", deny_unknown_fields)]
pub enum Event {
    /// A boot starts (0: power-on).
    Boot { n: usize, ns: f64 },
    /// Bytes of the defmt log, stamped with the first.
    Rtt { ns: f64, hex: Hex },
    /// A watched pin changed level (`reset`: a reset released it).
    Edge {
        pin: u8,
        high: bool,
        ns: f64,
        reset: Option<bool>,
    },
    /// The script drove an input pin.
    Drive { pin: u8, high: bool, ns: f64 },
    /// A PWM compare register write.
    Cc { slice: u8, value: u32, ns: f64 },
    /// A PWM slice enabled or disabled.
    En { slice: u8, on: bool, ns: f64 },
    /// One call of the probed function (the frame update).
    Call { cycles: u64, ns: f64 },
    /// The watchdog fired.
    Watchdog { ns: f64, reason: u32 },
    /// The power went off; the next boot follows.
    PowerCycle { ns: f64 },
    /// The boot ROM erased or programmed flash.
    Flash {
        op: Op,
        addr: u64,
        len: u64,
        busy_ns: f64,
        ns: f64,
    },
    /// The lowest stack address written in a boot.
    Stack { n: usize, low: u64 },
    /// Bytes UART0 sent, stamped with the first.
    Uart { ns: f64, hex: Hex },
    /// A UART script's last byte went onto UART0's RX line.
    UartRx { ns: f64, n: usize },
    /// A scripted byte found UART0's RX FIFO full.
    UartOverrun { ns: f64 },
    /// The USB host configured the device.
    UsbConnected { ns: f64 },
    /// Bytes the device sent on its CDC-ACM port.
    Usb { ns: f64, hex: Hex },
    /// The USB host sent a scripted chunk.
    UsbIn { ns: f64, n: usize },
    /// A DMX frame carrying a change ended.
    Dmx { ns: f64, frame: u64, changed: bool },
    /// The radar frames sent in the run, at its end.
    Radar { ns: f64, frames: u64 },
    /// Accesses to a register rp2040js does not model, over the run.
    Unmodelled(Unmodelled),
    /// A complaint of the emulator.
    Emu { level: Level, msg: String },
    /// The run is over.
    End(End),
}

/// Bytes, from hex digits.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct Hex(#[serde(with = "hex")] pub Vec<u8>);

/// Accesses to one register the emulator does not model.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Unmodelled {
    /// The peripheral as rp2040js names it, the register's offset in it.
    pub peripheral: String,
    pub op: Op,
    pub offset: u32,
    pub count: u64,
}

/// How the harness ended.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct End {
    pub why: Why,
    pub ns: f64,
    pub instructions: u64,
    pub wall_ms: u64,
    #[serde(default, rename = "msg")]
    pub error: Option<String>,
}

impl End {
    /// How a run ended: its last `end` event.
    pub fn of(events: &[Event]) -> Result<Self> {
        let end = events.iter().rev().find_map(|e| match e {
            Event::End(end) => Some(end.clone()),
            _ => None,
        });
        end.context("the emulator harness ended without saying how")
    }

    /// Why the run did not reach its virtual time, if it did not.
    pub fn problem(&self, silence: Duration) -> Option<String> {
        let at = self.ns / 1e9;
        let stuck = "the emulator made no progress";
        Some(match self.why {
            Why::Time => return None,
            Why::Silent => format!(
                "{stuck}: no log byte and no pin edge for {} s of virtual time (stopped at \
                 {at:.3} s)",
                silence.as_secs_f64()
            ),
            Why::Asleep => {
                format!("{stuck}: the core sleeps with nothing left to wake it (at {at:.3} s)")
            }
            Why::Wall => format!(
                "{stuck} in time: stopped after {:.1} s of wall time at {at:.3} s of virtual time \
                 (raise with --timeout)",
                Duration::from_millis(self.wall_ms).as_secs_f64()
            ),
            Why::Break => format!("the firmware hit a breakpoint at {at:.3} s"),
            Why::Closed => format!("the live run's input closed at {at:.3} s"),
            Why::Error => format!(
                "the emulator stopped (error) at {at:.3} s: {}",
                self.error.as_deref().unwrap_or("no reason given")
            ),
        })
    }
}

/// A flash operation of the boot ROM, or an access to an unmodelled register.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Op {
    Erase,
    Program,
    Read,
    Write,
}

/// How serious an emulator's complaint is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Level {
    Warn,
    Error,
}

/// Why the harness stopped (see [`End::problem`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Why {
    Time,
    Silent,
    Asleep,
    Wall,
    Break,
    Closed,
    #[default]
    Error,
}

impl Event {
    /// Reads one line of the harness's output.
    pub fn parse(line: &str) -> Result<Self> {
        // Through a `Value`: defmt-decoder turns on serde_json's
        // `arbitrary_precision`, under which a number read straight into a
        // tagged enum arrives as a map (serde-rs/json#505, #1046); a `Value`
        // hands it on as the number it is.
        serde_json::from_str::<serde_json::Value>(line)
            .and_then(serde_json::from_value)
            .with_context(|| {
                format!("the harness printed a line that is not a known event: {line}")
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_event_of_the_harness_reads_and_nothing_else() {
        let rtt = Event::parse(r#"{"ev":"rtt","ns":12.5,"hex":"00ff10"}"#).unwrap();
        assert_eq!(
            rtt,
            Event::Rtt {
                ns: 12.5,
                hex: Hex(vec![0, 0xff, 0x10])
            }
        );
        let edge = Event::parse(r#"{"ev":"edge","pin":16,"high":false,"ns":3,"reset":true}"#);
        let want = Event::Edge {
            pin: 16,
            high: false,
            ns: 3.0,
            reset: Some(true),
        };
        assert_eq!(edge.unwrap(), want);
        for line in [
            r#"{"ev":"boot","n":0,"ns":0}"#,
            r#"{"ev":"edge","pin":16,"high":true,"ns":3}"#,
            r#"{"ev":"flash","op":"program","addr":270532608,"len":256,"busy_ns":400000,"ns":9}"#,
            r#"{"ev":"unmodelled","peripheral":"ROSC_BASE","op":"write","offset":16,"count":3}"#,
            r#"{"ev":"end","why":"error","msg":"boom","ns":0,"instructions":0,"wall_ms":5}"#,
            r#"{"ev":"cc","slice":0,"value":4800,"ns":1}"#,
            r#"{"ev":"en","slice":1,"on":true,"ns":1}"#,
            r#"{"ev":"call","cycles":900,"ns":1}"#,
            r#"{"ev":"watchdog","ns":1,"reason":1}"#,
            r#"{"ev":"power_cycle","ns":1}"#,
            r#"{"ev":"stack","n":0,"low":537133056}"#,
            r#"{"ev":"uart","ns":1,"hex":"6f6b0d0a"}"#,
            r#"{"ev":"uart_rx","ns":1,"n":12}"#,
            r#"{"ev":"uart_overrun","ns":1}"#,
            r#"{"ev":"usb_connected","ns":1}"#,
            r#"{"ev":"usb","ns":1,"hex":""}"#,
            r#"{"ev":"usb_in","ns":1,"n":3}"#,
            r#"{"ev":"dmx","ns":1,"frame":4,"changed":true}"#,
            r#"{"ev":"drive","pin":2,"high":true,"ns":1}"#,
            r#"{"ev":"emu","level":"warn","msg":"[RP2040] something"}"#,
            r#"{"ev":"end","why":"time","ns":1,"instructions":2,"wall_ms":3}"#,
        ] {
            assert!(Event::parse(line).is_ok(), "{line}");
        }
        for line in [
            r#"{"ev":"teleport","ns":1}"#,
            r#"{"ns":1}"#,
            r#"{"ev":"boot","n":0,"ns":0,"extra":1}"#,
            r#"{"ev":"boot","ns":0}"#,
            r#"{"ev":"edge","pin":16,"high":"yes","ns":3}"#,
            r#"{"ev":"rtt","ns":1,"hex":"0g"}"#,
            r#"{"ev":"end","why":"bored","ns":1,"instructions":2,"wall_ms":3}"#,
            r#"{"ev":"emu","level":"info","msg":"x"}"#,
            "not json",
        ] {
            let err = format!("{:#}", Event::parse(line).unwrap_err());
            assert!(err.contains("not a known event"), "{line}: {err}");
        }
    }
}
