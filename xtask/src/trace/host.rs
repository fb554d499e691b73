//! What runs beside the frame task, on the host: the console's service, the
//! input task (woken as on the board) and the telemetry of `watch <hz>`.

use idle_head_core::behaviour::{CommandQueue, RestState, ShowLink};
use idle_head_core::console::{
    ActionLine, ConsoleLink, ConsoleService, HeadStatus, PORT_REPLY, Response, TELEMETRY_LINE,
    respond, telemetry_line,
};
use idle_head_core::driver::DriverConfig;
use idle_head_core::input::{Inputs, Micros, Pull, SLOTS};
use idle_head_core::servo::ServoRate;
use idle_head_core::settings::{RamStorage, Settings, SettingsSource};

use super::{Event, Kind};

/// The console's service and the input task, with the origin of each
/// action they queued, oldest first: the command as written (or what to
/// call its source) and its script line (0: not a script's motion line).
pub struct Beside<'a> {
    service: ConsoleService<'a, RamStorage>,
    queue: &'a CommandQueue,
    link: &'a ConsoleLink,
    pub origins: Vec<(String, usize)>,
    inputs: Inputs,
    /// The levels pin lines set (`None`: the input's idle level).
    driven: [Option<bool>; SLOTS],
    /// When the input task wakes next at the latest, µs.
    deadline: Option<u64>,
    /// The radar's presence as the link says (`None`: off).
    pub radar: Option<u32>,
}

impl<'a> Beside<'a> {
    /// Both as the board starts them, on the built-in settings at `rate`.
    pub fn new(
        queue: &'a CommandQueue,
        link: &'a ConsoleLink,
        show: &'a ShowLink,
        rate: ServoRate,
    ) -> anyhow::Result<Self> {
        let settings = Settings {
            rate,
            ..Settings::DEFAULT
        };
        let source = if rate == ServoRate::DEFAULT {
            SettingsSource::Defaults
        } else {
            SettingsSource::Changed
        };
        let config = DriverConfig::DEFAULT;
        let service = ConsoleService::new(queue, link, RamStorage::new(), config, settings, source)
            .map_err(|e| anyhow::anyhow!("the built-in settings: {e}"))?
            .with_show(show)
            .with_parts(crate::board::pico_parts());
        Ok(Self {
            service,
            queue,
            link,
            origins: Vec::new(),
            inputs: Inputs::new(&link.input_settings(), Micros(0)),
            driven: [None; SLOTS],
            deadline: Some(0),
            radar: None,
        })
    }

    /// Carries out the console line `line`: its reply, and whether it queued
    /// an action (a motion line; a `load` or `defaults` may, the idle
    /// amplitude). A motion line's reply is its check's `ok`: the frame that
    /// takes the action says what it started (the trace marks it).
    pub fn line(&mut self, line: &str) -> (String, bool) {
        let before = self.queue.len();
        let mut out = [0; PORT_REPLY];
        let reply = match respond(Ok(line.as_bytes()), &mut self.service, &mut out) {
            Response::Now(reply) => reply,
            Response::Later(later) => later.finish(&mut out, |_| {}),
        };
        let text = String::from_utf8_lossy(reply).trim_end().to_owned();
        (text, self.queue.len() > before)
    }

    /// Takes `event` with the head in `rest`; `false` if it has to wait
    /// for the next frame (the queue is full).
    pub fn take(&mut self, event: &Event, rest: RestState) -> bool {
        match event.kind {
            Kind::Act(action) => {
                if self.queue.try_submit(action).is_err() {
                    // A console would be told `err busy`; the script waits.
                    let (line, ms, text) = (event.line, event.at_us / 1000, &event.text);
                    println!("line {line}: command queue full at {ms} ms, `{text}` waits a frame");
                    return false;
                }
                self.origins.push((event.text.clone(), event.line));
                return true;
            }
            Kind::Console => {
                let (reply, queued) = self.line(&event.text);
                println!("{:>9} ms  {}: {reply}", event.at_us / 1000, event.text);
                if queued {
                    self.origins.push((event.text.clone(), 0));
                }
            }
            Kind::Pin { input, high } => {
                let slot = crate::board::pico_parts().inputs.slot(input);
                if let Some(level) = slot.and_then(|i| self.driven.get_mut(i)) {
                    *level = Some(high);
                }
            }
            // Taken by the frame loop.
            Kind::Radar(_) => return true,
        }
        // The input task takes new settings and levels at once.
        self.wake(event.at_us, rest);
        true
    }

    /// The input task's wakes at its deadlines up to `until` µs.
    pub fn wake_until(&mut self, until: u64, rest: RestState) {
        while let Some(at) = self.deadline.filter(|&at| at <= until) {
            self.wake(at, rest);
            if self.deadline == Some(at) {
                break;
            }
        }
    }

    /// One wake of the input task at `now` µs, the head in `rest`.
    fn wake(&mut self, now: u64, rest: RestState) {
        let settings = self.link.input_settings();
        if self.link.take_inputs_changed() {
            self.inputs.configure(&settings, Micros(now));
        }
        let levels = (0..SLOTS).fold(0, |bits, i| {
            let idle = settings.roles[i].pull() == Pull::Up;
            bits | (u8::from(self.driven[i].unwrap_or(idle)) << i)
        });
        self.inputs.sense(Micros(now), self.radar);
        let resting = rest == RestState::Resting;
        (self.inputs).update(&settings, Micros(now), levels, resting);
        let mut full = false;
        while let Some(action) = self.inputs.pending(&settings) {
            if self.queue.try_submit(action).is_err() {
                full = true;
                break;
            }
            self.origins
                .push((format!("inputs: {}", ActionLine(&action)), 0));
            self.inputs.sent();
        }
        self.link.publish_inputs(self.inputs.status(&settings));
        self.deadline = if full {
            Some(now + 5000)
        } else {
            self.inputs.deadline(&settings).map(|at| at.0)
        };
    }
}

/// A stream of telemetry lines (no line ends): the core's own line of the
/// status the first frame at or after each tick published.
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
        self.next_us = (t_us / self.period_us + 1) * self.period_us;
        let mut out = [0; TELEMETRY_LINE];
        let line = telemetry_line(status, 0, &mut out);
        let line = String::from_utf8_lossy(line).trim_end().to_owned();
        self.lines.push(line);
    }
}
