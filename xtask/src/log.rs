//! The decoded defmt log of a QEMU run.

use std::{path::Path, time::Duration};

use anyhow::{Context, Result};
use defmt_decoder::{DecodeError, Frame, Locations, StreamDecoder, Table};

use crate::project::Exit;

/// An ELF's defmt table, and its source locations (if it has debug info).
pub struct Defmt {
    table: Table,
    locations: Option<Locations>,
}

impl Defmt {
    pub fn read(elf: &Path) -> Result<Self> {
        let bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
        let table = Table::parse(&bytes)
            .with_context(|| format!("reading the defmt table of {}", elf.display()))?
            .with_context(|| format!("{} has no defmt data", elf.display()))?;
        let locations = table.get_locations(&bytes).ok();
        Ok(Self { table, locations })
    }

    /// A decoder for one stream (a run, a boot).
    pub fn stream(&self) -> Box<dyn StreamDecoder + '_> {
        self.table.new_stream_decoder()
    }

    /// Feeds `bytes` to `decoder`; the lines they complete.
    pub fn lines(&self, decoder: &mut dyn StreamDecoder, bytes: &[u8]) -> Vec<LogLine> {
        decoder.received(bytes);
        let mut lines = Vec::new();
        loop {
            match decoder.decode() {
                Ok(frame) => lines.push(self.line(&frame)),
                Err(DecodeError::UnexpectedEof) => return lines,
                Err(DecodeError::Malformed) => lines.push(LogLine::new(
                    "ERROR",
                    "(malformed defmt frame: the log stream is corrupt)",
                )),
            }
        }
    }

    /// The line of a decoded frame, its location relative to the root.
    fn line(&self, frame: &Frame<'_>) -> LogLine {
        let location = (self.locations.as_ref())
            .and_then(|locations| locations.get(&frame.index()))
            .map(|location| {
                let file = crate::project::relative(&location.file);
                format!("{}:{}", file.display(), location.line)
            });
        LogLine {
            level: frame.level().map(|level| level.as_str().to_uppercase()),
            message: frame.display_message().to_string(),
            timestamp: frame.display_timestamp().map(|t| t.to_string()),
            location,
        }
    }
}

/// One decoded defmt frame.
#[derive(Debug, Clone)]
pub struct LogLine {
    /// `INFO`, `WARN`, ... (`None` for `println!`-style frames).
    pub level: Option<String>,
    pub message: String,
    /// The formatted timestamp, if the firmware has one.
    pub timestamp: Option<String>,
    /// `file:line` of the log statement, if the ELF has debug info.
    pub location: Option<String>,
}

impl LogLine {
    /// A line with a level and a message only.
    pub fn new(level: &str, message: impl Into<String>) -> Self {
        Self {
            level: Some(level.to_owned()),
            message: message.into(),
            timestamp: None,
            location: None,
        }
    }

    /// The line as kept in the expected log: no timestamp or location
    /// (those change with unrelated code).
    pub fn snapshot(&self) -> String {
        match &self.level {
            Some(level) => format!("{level:<5} {}", self.message),
            None => self.message.clone(),
        }
    }

    pub fn is_problem(&self) -> bool {
        matches!(self.level.as_deref(), Some("WARN" | "ERROR"))
    }

    /// Prints the line with its timestamp, and the location of a problem.
    pub fn print(&self) {
        let timestamp = self.timestamp.as_ref().map(|t| format!("{t} "));
        println!("{}{}", timestamp.unwrap_or_default(), self.snapshot());
        if self.is_problem()
            && let Some(location) = &self.location
        {
            println!("      └─ {location}");
        }
    }
}

/// The outcome of one QEMU run.
#[derive(Debug)]
pub struct Run {
    pub log: Vec<LogLine>,
    pub exit: Exit,
    pub elapsed: Duration,
}

impl Run {
    /// Whether QEMU exited with 0 before the timeout.
    pub fn succeeded(&self) -> bool {
        matches!(self.exit, Exit::Status(status) if status.success())
    }

    /// One line saying how the run ended.
    pub fn describe(&self) -> String {
        let how = match self.exit {
            Exit::Status(status) if status.success() => "firmware exited with success".to_owned(),
            Exit::Status(status) => format!("firmware FAILED ({status})"),
            Exit::TimedOut(limit) => format!(
                "firmware TIMED OUT: QEMU killed after {} s (raise with --timeout)",
                limit.as_secs()
            ),
        };
        format!(
            "qemu: {how}; {} log lines in {:.1} s",
            self.log.len(),
            self.elapsed.as_secs_f64()
        )
    }

    /// The log as kept on file: one [`LogLine::snapshot`] a line.
    pub fn text(&self) -> String {
        self.log.iter().map(|line| line.snapshot() + "\n").collect()
    }
}

/// The message of the last `summary key=value ...` line of `log`.
pub fn summary(log: &[LogLine]) -> Option<&str> {
    let line = log.iter().rfind(|line| line.message.starts_with("summary"));
    line.map(|line| line.message.as_str())
}

/// The value of `key=` among the words of `message` (separated by spaces
/// or commas).
pub fn field<'a>(message: &'a str, key: &str) -> Option<&'a str> {
    let mut words = message.split(|c: char| c.is_whitespace() || c == ',');
    words.find_map(|word| word.strip_prefix(key)?.strip_prefix('='))
}

/// The [`field`] `key` of `message` as a number: decimal, or hexadecimal
/// with `0x`, `_` separators allowed.
pub fn number(message: &str, key: &str) -> Result<u64> {
    let value = field(message, key).with_context(|| format!("`{message}` has no `{key}=`"))?;
    let digits = value.replace('_', "");
    let parsed = match digits.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16),
        None => digits.parse(),
    };
    parsed.with_context(|| format!("`{key}={value}` in `{message}` is not a whole number"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_last_summary_line_and_its_numbers() {
        let log = [
            "frame 0 pitch=0 roll=0 yaw=0",
            "summary frames=10 missed=3",
            "summary frames=900 missed=0 pulse_violations=0, checksum=0x1a2b_3c4d",
        ]
        .map(|message| LogLine::new("INFO", message));
        let line = summary(&log).unwrap();
        assert_eq!(number(line, "frames").unwrap(), 900);
        assert_eq!(number(line, "missed").unwrap(), 0);
        assert_eq!(number(line, "checksum").unwrap(), 0x1a2b_3c4d);
        assert!(number(line, "absent").is_err());
        assert!(number("x=1e3", "x").is_err());
        assert!(summary(&log[..1]).is_none());
        // The expected log keeps level and message only.
        let mut line = LogLine::new("INFO", "hello");
        line.timestamp = Some("1.000000".to_owned());
        assert_eq!(line.snapshot(), "INFO  hello");
    }
}
