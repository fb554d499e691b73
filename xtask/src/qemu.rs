//! Runs the QEMU image and decodes its defmt log; `cargo xtask qemu`.

use std::{
    io::Read,
    path::Path,
    process::{Child, Command, ExitStatus, Stdio},
    sync::mpsc::{self, RecvTimeoutError},
    thread,
    time::{Duration, Instant},
};

use anyhow::{Context, Result, bail};
use defmt_decoder::{DecodeError, Frame, Locations, Table};

use crate::{
    Options,
    project::{self, QEMU},
    reference, render, setup, snapshot,
};

/// `cargo xtask qemu`: build, run, show. `Ok(false)` when the run failed.
pub fn command(options: Options) -> Result<bool> {
    let root = project::root();
    setup::ensure_toolchain(&root)?;
    setup::ensure_qemu()?;
    let metadata = project::metadata(&root)?;
    QEMU.build(&root)?;
    let elf = QEMU.elf(&metadata);
    let run = run(&elf, options.timeout, Echo::All)?;

    if let Some(plot) = render::plot(&run.log) {
        println!();
        print!("{plot}");
    }
    println!();
    println!("{}", run.describe());
    let mut ok = run.succeeded();
    match check_summary(&run.log) {
        Ok(line) => println!("{line}"),
        Err(error) => {
            println!("summary check failed: {error:#}");
            ok = false;
        }
    }
    if options.bless {
        if run.succeeded() {
            snapshot::bless(&run)?;
        } else {
            println!("not re-recording the expected log: the run failed");
        }
    }
    Ok(ok)
}

/// How much of the log to print while QEMU runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Echo {
    /// Every decoded line.
    All,
    /// Warnings and errors only (with their source location).
    Problems,
}

/// One decoded defmt frame.
#[derive(Debug, Clone)]
pub struct LogLine {
    /// `INFO`, `WARN`, ... (`None` for `println!`-style frames).
    pub level: Option<String>,
    /// The formatted message.
    pub message: String,
    /// The formatted timestamp, if the firmware has one.
    pub timestamp: Option<String>,
    /// `file:line` of the log statement, if the ELF has debug info.
    pub location: Option<String>,
}

impl LogLine {
    fn from_frame(frame: &Frame<'_>, locations: Option<&Locations>, root: &Path) -> Self {
        let location = locations
            .and_then(|locations| locations.get(&frame.index()))
            .map(|location| {
                let file = location.file.strip_prefix(root).unwrap_or(&location.file);
                format!("{}:{}", file.display(), location.line)
            });
        Self {
            level: frame.level().map(|level| level.as_str().to_uppercase()),
            message: frame.display_message().to_string(),
            timestamp: frame.display_timestamp().map(|t| t.to_string()),
            location,
        }
    }

    fn malformed() -> Self {
        Self {
            level: Some("ERROR".to_owned()),
            message: "(malformed defmt frame: the log stream is corrupt)".to_owned(),
            timestamp: None,
            location: None,
        }
    }

    /// The line as kept in the expected log: level and message, no timestamp
    /// or location (those change with unrelated code changes).
    pub fn snapshot(&self) -> String {
        match &self.level {
            Some(level) => format!("{level:<5} {}", self.message),
            None => self.message.clone(),
        }
    }

    /// Whether this is a warning or an error.
    pub fn is_problem(&self) -> bool {
        matches!(self.level.as_deref(), Some("WARN" | "ERROR"))
    }

    fn print(&self) {
        match &self.timestamp {
            Some(timestamp) => println!("{timestamp} {}", self.snapshot()),
            None => println!("{}", self.snapshot()),
        }
        if self.is_problem()
            && let Some(location) = &self.location
        {
            println!("      └─ {location}");
        }
    }
}

/// How QEMU ended.
#[derive(Debug, Clone, Copy)]
pub enum Exit {
    /// QEMU exited (semihosting exit code, 0 = success).
    Status(ExitStatus),
    /// Killed after the timeout.
    TimedOut(Duration),
}

/// The outcome of one QEMU run.
#[derive(Debug)]
pub struct Run {
    /// Decoded log, in order.
    pub log: Vec<LogLine>,
    /// How QEMU ended.
    pub exit: Exit,
    /// Wall time of the run.
    pub elapsed: Duration,
}

impl Run {
    /// QEMU exited with status 0 before the timeout.
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
}

/// QEMU's command line for `elf`. `-icount shift=0` makes one instruction one
/// nanosecond of virtual time, so timing repeats exactly run after run;
/// `sleep=off` lets the virtual clock jump over the time the core sleeps
/// instead of following the wall clock, which would make wake-up times (and
/// so the log) vary from run to run, and the run slower.
pub fn qemu_command(elf: &Path) -> Command {
    let mut command = Command::new(setup::QEMU_BINARY);
    command
        .args(["-machine", "lm3s6965evb", "-cpu", "cortex-m0", "-nographic"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(["-icount", "shift=0,sleep=off"])
        .arg("-kernel")
        .arg(elf);
    command
}

/// Runs `elf` in QEMU, decoding its defmt output as it arrives.
pub fn run(elf: &Path, timeout: Duration, echo: Echo) -> Result<Run> {
    let root = project::root();
    let bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let table = Table::parse(&bytes)
        .with_context(|| format!("reading the defmt table of {}", elf.display()))?
        .with_context(|| format!("{} has no defmt data", elf.display()))?;
    // Locations need debug info; without them the log still decodes.
    let locations = table.get_locations(&bytes).ok();
    let mut decoder = table.new_stream_decoder();

    let mut command = qemu_command(elf);
    command.stdin(Stdio::null()).stdout(Stdio::piped());
    println!("$ {}", project::display(&command));
    let start = Instant::now();
    let mut child = command
        .spawn()
        .with_context(|| format!("could not start {}", setup::QEMU_BINARY))?;

    // A reader thread feeds stdout through a channel so that the wait for
    // output can time out.
    let mut stdout = child.stdout.take().context("QEMU's stdout")?;
    let (sender, receiver) = mpsc::channel::<Vec<u8>>();
    let reader = thread::spawn(move || {
        let mut buffer = [0_u8; 4096];
        while let Ok(n @ 1..) = stdout.read(&mut buffer) {
            if sender.send(buffer[..n].to_vec()).is_err() {
                break;
            }
        }
    });

    let deadline = start + timeout;
    let mut log = Vec::new();
    let mut timed_out = false;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match receiver.recv_timeout(left) {
            Ok(chunk) => {
                decoder.received(&chunk);
                loop {
                    let line = match decoder.decode() {
                        Ok(frame) => LogLine::from_frame(&frame, locations.as_ref(), &root),
                        Err(DecodeError::UnexpectedEof) => break,
                        Err(DecodeError::Malformed) => LogLine::malformed(),
                    };
                    if echo == Echo::All || line.is_problem() {
                        line.print();
                    }
                    log.push(line);
                }
            }
            Err(RecvTimeoutError::Timeout) => {
                timed_out = true;
                break;
            }
            Err(RecvTimeoutError::Disconnected) => break,
        }
    }

    let status = if timed_out {
        None
    } else {
        wait_until(&mut child, deadline)?
    };
    let exit = if let Some(status) = status {
        Exit::Status(status)
    } else {
        kill(&mut child);
        Exit::TimedOut(timeout)
    };
    let _ = reader.join();
    Ok(Run {
        log,
        exit,
        elapsed: start.elapsed(),
    })
}

fn wait_until(child: &mut Child, deadline: Instant) -> Result<Option<ExitStatus>> {
    loop {
        if let Some(status) = child.try_wait().context("waiting for QEMU")? {
            return Ok(Some(status));
        }
        if Instant::now() >= deadline {
            return Ok(None);
        }
        thread::sleep(Duration::from_millis(20));
    }
}

fn kill(child: &mut Child) {
    let _ = child.kill();
    let _ = child.wait();
}

/// The firmware's closing `summary key=value ...` line, as fields.
#[derive(Debug)]
pub struct Summary {
    fields: Vec<(String, String)>,
}

impl Summary {
    /// Finds the last line of `log` whose message starts with `summary`.
    pub fn find(log: &[LogLine]) -> Option<Self> {
        let line = log
            .iter()
            .rev()
            .find(|line| line.message.trim_start().starts_with("summary"))?;
        let fields = line
            .message
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter_map(|token| token.split_once('='))
            .map(|(key, value)| (key.to_owned(), value.to_owned()))
            .collect();
        Some(Self { fields })
    }

    /// The value of `key`, if present.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, value)| value.as_str())
    }

    /// The value of `key` as a number (decimal, or hexadecimal with `0x`).
    pub fn number(&self, key: &str) -> Result<u64> {
        let value = self
            .get(key)
            .with_context(|| format!("the summary line has no `{key}=`"))?;
        let parsed = match value
            .strip_prefix("0x")
            .or_else(|| value.strip_prefix("0X"))
        {
            Some(hex) => u64::from_str_radix(&hex.replace('_', ""), 16),
            None => value.replace('_', "").parse(),
        };
        parsed.with_context(|| format!("`{key}={value}` in the summary line is not a number"))
    }
}

/// Checks the summary line: no missed frames, no pulse violations, and the
/// checksum of the loops the firmware generated equals the one generated on
/// the host by the same core library. Returns a one-line verdict.
pub fn check_summary(log: &[LogLine]) -> Result<String> {
    let summary = Summary::find(log).context("the log has no `summary ...` line")?;
    let missed = summary.number("missed")?;
    let violations = summary.number("pulse_violations")?;
    let firmware = summary.number("checksum")?;
    let host = reference::checksum()?;
    let mut problems = Vec::new();
    if missed != 0 {
        problems.push(format!("missed={missed} (want 0)"));
    }
    if violations != 0 {
        problems.push(format!("pulse_violations={violations} (want 0)"));
    }
    if firmware != u64::from(host) {
        problems.push(format!(
            "checksum={firmware:#010x} but the host computes {host:#010x}"
        ));
    }
    if problems.is_empty() {
        Ok(format!(
            "summary ok: missed=0 pulse_violations=0 checksum={host:#010x} (matches the host)"
        ))
    } else {
        bail!("{}", problems.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(message: &str) -> LogLine {
        LogLine {
            level: Some("INFO".to_owned()),
            message: message.to_owned(),
            timestamp: None,
            location: None,
        }
    }

    #[test]
    fn reads_the_last_summary_line() {
        let log = [
            line("frame 0 pitch=0 roll=0 yaw=0"),
            line("summary frames=10 missed=3"),
            line("summary frames=900 missed=0 pulse_violations=0, checksum=0x1a2B_3c4d"),
        ];
        let summary = Summary::find(&log).unwrap();
        assert_eq!(summary.number("frames").unwrap(), 900);
        assert_eq!(summary.number("missed").unwrap(), 0);
        assert_eq!(summary.number("checksum").unwrap(), 0x1a2b_3c4d);
        assert!(summary.number("absent").is_err());
        assert!(Summary::find(&log[..1]).is_none());
    }

    #[test]
    fn snapshot_lines_have_level_and_message_only() {
        let mut with_extras = line("hello");
        with_extras.timestamp = Some("1.000000".to_owned());
        with_extras.location = Some("src/main.rs:3".to_owned());
        assert_eq!(with_extras.snapshot(), "INFO  hello");
    }
}
