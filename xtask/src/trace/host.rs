//! What runs beside the frame task on a board, on the host: the console's
//! service and the input task, the same core code as the firmware's, on the
//! trace's queue and link. The input task wakes as on the board: at a pin's
//! change, at its deadlines, and when the console changes its settings.

use idle_head_core::behaviour::{CommandQueue, RestState, ShowLink};
use idle_head_core::console::{ActionLine, ConsoleLink, ConsoleService, Response, respond};
use idle_head_core::driver::DriverConfig;
use idle_head_core::input::{InputSettings, Inputs, Micros, Pull, SLOTS};
use idle_head_core::servo::ServoRate;
use idle_head_core::settings::{RamStorage, Settings, SettingsSource};

/// Where an action in the queue came from.
#[derive(Debug, Clone)]
pub enum Origin {
    /// A script line, by its index in the script's events.
    Line(usize),
    /// The console's service or an input: what to call it.
    Other(String),
}

/// The console's service on the host, with the trace's queue and link.
pub struct Console<'a> {
    service: ConsoleService<'a, RamStorage>,
    queue: &'a CommandQueue,
}

impl<'a> Console<'a> {
    /// The service on the built-in settings at `rate`.
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
        let service = ConsoleService::new(
            queue,
            link,
            RamStorage::new(),
            DriverConfig::DEFAULT,
            settings,
            source,
        )
        .map_err(|e| anyhow::anyhow!("the built-in settings: {e}"))?
        .with_show(show)
        .with_parts(crate::board::pico_parts());
        Ok(Self { service, queue })
    }

    /// Carries out `line`; returns its reply, and whether it queued an
    /// action (a motion line, and a `load` or `defaults` may: the idle
    /// amplitude). The reply to a motion line waits for the frame task on a
    /// board; here it is its check's `ok`, and the frame that takes the
    /// action says what it started (the trace marks it).
    pub fn line(&mut self, line: &str) -> (String, bool) {
        let before = self.queue.len();
        let mut out = [0; idle_head_core::console::PORT_REPLY];
        let later = match respond(Ok(line.as_bytes()), &mut self.service, &mut out) {
            Response::Now(reply) => return (text(reply), self.queue.len() > before),
            Response::Later(later) => later,
        };
        let reply = later.finish(&mut out, |_| {});
        (text(reply), self.queue.len() > before)
    }
}

/// A reply line as text, without its line end.
fn text(reply: &[u8]) -> String {
    String::from_utf8_lossy(reply).trim_end().to_owned()
}

/// The input task on the host; see the [module docs](self).
pub struct Task {
    inputs: Inputs,
    /// The levels a pin line set (`None`: the input's idle level).
    driven: [Option<bool>; SLOTS],
    /// When the task wakes next at the latest, µs.
    deadline: Option<u64>,
    /// The radar's presence as the link says (`None`: off).
    radar: Option<u32>,
}

impl Task {
    /// The task as the board starts it, at 0.
    pub fn new(link: &ConsoleLink) -> Self {
        Self {
            inputs: Inputs::new(&link.input_settings(), Micros(0)),
            driven: [None; SLOTS],
            deadline: Some(0),
            radar: None,
        }
    }

    /// The level input `input` (2 to 5) is driven to from now on.
    pub fn drive(&mut self, input: u8, high: bool) {
        let slot = crate::board::pico_parts().inputs.slot(input);
        if let Some(level) = slot.and_then(|i| self.driven.get_mut(i)) {
            *level = Some(high);
        }
    }

    /// The radar's presence the task reads at its next wakes.
    pub const fn radar(&mut self, presence: Option<u32>) {
        self.radar = presence;
    }

    /// When the task wakes next without a change, µs.
    pub const fn deadline(&self) -> Option<u64> {
        self.deadline
    }

    /// The levels the task reads under `settings`.
    fn levels(&self, settings: &InputSettings) -> u8 {
        (0..SLOTS).fold(0, |bits, i| {
            let idle = settings.roles[i].pull() == Pull::Up;
            if self.driven[i].unwrap_or(idle) {
                bits | (1 << i)
            } else {
                bits
            }
        })
    }

    /// One wake at `now` µs, the head in `rest`: the actions it sends go
    /// into `queue`, each with its origin into `origins`.
    pub fn wake(
        &mut self,
        now: u64,
        rest: RestState,
        link: &ConsoleLink,
        queue: &CommandQueue,
        origins: &mut Vec<Origin>,
    ) {
        let settings = link.input_settings();
        if link.take_inputs_changed() {
            self.inputs.configure(&settings, Micros(now));
        }
        let levels = self.levels(&settings);
        self.inputs.sense(Micros(now), self.radar);
        self.inputs
            .update(&settings, Micros(now), levels, rest == RestState::Resting);
        let mut full = false;
        while let Some(action) = self.inputs.pending(&settings) {
            if queue.try_submit(action).is_err() {
                full = true;
                break;
            }
            origins.push(Origin::Other(format!("inputs: {}", ActionLine(&action))));
            self.inputs.sent();
        }
        link.publish_inputs(self.inputs.status(&settings));
        self.deadline = if full {
            Some(now + 5000)
        } else {
            self.inputs.deadline(&settings).map(|at| at.0)
        };
    }
}
