//! The telemetry lines a port would stream during a trace (`watch <hz>`):
//! the core's own line ([`telemetry_line`]) of the status each frame
//! publishes, the first frame at or after each of the stream's ticks, as
//! a port's console writes it from what the last frame left.

use idle_head_core::console::{HeadStatus, TELEMETRY_LINE, telemetry_line};

/// A stream of telemetry lines: its tick's period and next tick (µs), the
/// lines so far (without their line ends).
#[derive(Debug, Clone)]
pub struct Watch {
    period_us: u64,
    next_us: u64,
    pub lines: Vec<String>,
}

impl Watch {
    /// A stream of `hz` lines a second from the first frame on.
    pub fn new(hz: u8) -> Self {
        Self {
            period_us: 1_000_000 / u64::from(hz.max(1)),
            next_us: 0,
            lines: Vec::new(),
        }
    }

    /// The frame at `t_us` published `status`: its line, if a tick is due.
    pub fn frame(&mut self, t_us: u64, status: &HeadStatus) {
        if t_us < self.next_us {
            return;
        }
        while self.next_us <= t_us {
            self.next_us += self.period_us;
        }
        let mut out = [0; TELEMETRY_LINE];
        let line = telemetry_line(status, 0, &mut out);
        let line = String::from_utf8_lossy(line).trim_end().to_owned();
        self.lines.push(line);
    }
}
