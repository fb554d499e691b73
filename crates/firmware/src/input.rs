//! Trigger inputs: what a board implements to give the levels of its
//! inputs ([`InputSource`]), and the input task's body ([`run`]), the same
//! on every board.
//!
//! The task is event-driven: it reads the levels when the source says one
//! may have changed, at the deadline the core's state machine asks for (a
//! level to confirm after its debounce time, the rest timer) and when the
//! console changes the inputs' settings; between those it sleeps. With no
//! input configured it never wakes but for a change of settings, and the
//! board behaves as it does without inputs. What a level means (debounce,
//! roles, the rest timer) is the core's ([`idle_head_core::input`]); the
//! actions go to the frame task's queue like the console's, and the levels
//! to the console's `status` through the console's link (both in
//! [`Links`]).
//!
//! The task runs in thread mode, below the frame task, as the console
//! tasks do. Like every embassy task, it is defined by the board (a task
//! defined here would be linked into every image): a board's task is one
//! line calling [`run`].
//!
//! A full queue (the console flooding it) holds the actions back: they are
//! sent, oldest first, a few milliseconds later. A button's action
//! reaches the queue within microseconds of its debounced edge, and the
//! frame task takes it before its next frame: it starts within a frame of
//! the edge.

use embassy_futures::select::{Either3, select3};
use embassy_time::{Duration, Instant, Timer};
use idle_head_core::console::HeadMode;
use idle_head_core::input::{InputIds, InputSettings, Inputs, Micros, Pull};

use crate::boot::Links;
use crate::log;

/// How long the task waits before it tries a full queue again.
pub const RETRY: Duration = Duration::from_millis(5);

// ANCHOR: source
/// Where the trigger inputs' levels come from: GPIO pins (`idle-head-rp`'s
/// `GpioInputs`), or anything else that has a level and can wait for it
/// to change (a bus message, a sensor on another link): as many inputs as
/// its [`ids`](Self::ids), up to [`SLOTS`](idle_head_core::input::SLOTS),
/// input `i` in slot `i` (bit `i` of the levels, role `i` of the settings).
///
/// A source reads levels and waits for them to change; it interprets
/// nothing (no debouncing, no roles). It must not block.
// The executors here are single-threaded: no `Send` bound is wanted on the
// futures, which is what the lint warns about.
#[allow(async_fn_in_trait)]
// ANCHOR: source
pub trait InputSource {
    /// Its inputs' numbers, as the console names them (the Pico's: its
    /// GPIO numbers, 2 to 5).
    fn ids(&self) -> InputIds;

    /// Sets input `i` (from 0) up with `pull`, the one its role needs (a
    /// source without pull resistors ignores it).
    fn set_pull(&mut self, i: usize, pull: Pull);

    /// The levels now: bit `i` set while input `i` is high.
    fn levels(&mut self) -> u8;

    /// Returns once one of the inputs in `watched` (bit `i`) is at
    /// another level than in `seen`: at once if one is already. A change
    /// in between the read of `seen` and this call must not be missed
    /// (wait for the other level, not for an edge).
    async fn changed(&mut self, seen: u8, watched: u8);
}
// ANCHOR_END: source

/// Sets every input's pull for its role in `settings`.
fn pulls(source: &mut impl InputSource, settings: &InputSettings) {
    for (i, role) in settings.roles.iter().enumerate() {
        source.set_pull(i, role.pull());
    }
}

/// `at`, as the core's state machine counts time.
fn micros(at: Instant) -> Micros {
    Micros(at.as_micros())
}

/// The input task's body: reads `source` with the roles in the console
/// link's settings (the boot's, then the console's, see
/// [`ConsoleLink::set_inputs`](idle_head_core::console::ConsoleLink::set_inputs)),
/// and sends what the inputs do to the frame task, all through `links`.
/// Never returns.
pub async fn run(source: &mut impl InputSource, links: &Links) -> ! {
    let link = &links.console;
    // (The settings are read in `start` and `step`, not kept across an
    // `.await`: the task's future holds no copy of them.)
    let mut inputs = start(source, links, Instant::now());
    let mut shown = Shown::default();
    let mut changed = false;
    loop {
        let wake = Wake {
            changed,
            now: Instant::now(),
        };
        let (levels, watched, deadline) = step(source, &mut inputs, &mut shown, wake, links);
        let timer = async {
            match deadline {
                Some(at) => Timer::at(at).await,
                None => core::future::pending().await,
            }
        };
        let event = select3(
            source.changed(levels, watched),
            timer,
            link.inputs_changed(),
        )
        .await;
        // (The wait took the signal of a change of settings.)
        changed = matches!(event, Either3::Third(()));
    }
}

/// The input task's start at `now`: the pulls for the settings in
/// `links` (the boot's: no change to take), and the state machine.
fn start(source: &mut impl InputSource, links: &Links, now: Instant) -> Inputs {
    let link = &links.console;
    let _ = link.take_inputs_changed();
    let settings = link.input_settings();
    pulls(source, &settings);
    log_roles(source.ids(), &settings);
    Inputs::new(&settings, micros(now))
}

/// What the log last said of the inputs.
#[derive(Default)]
struct Shown {
    active: u8,
    lost: u32,
}

/// Why and when the input task woke.
#[derive(Clone, Copy)]
struct Wake {
    /// The inputs' settings changed (the wait took the signal).
    changed: bool,
    /// The time of the wake.
    now: Instant,
}

/// One wake of the input task: new settings (if they changed), the
/// levels, the actions to the queue, the status to the link, all in
/// `links`. Returns the levels read, the inputs to watch and when to wake
/// at the latest.
fn step(
    source: &mut impl InputSource,
    inputs: &mut Inputs,
    shown: &mut Shown,
    wake: Wake,
    links: &Links,
) -> (u8, u8, Option<Instant>) {
    let link = &links.console;
    let now = micros(wake.now);
    let settings = link.input_settings();
    if wake.changed || link.take_inputs_changed() {
        inputs.configure(&settings, now);
        pulls(source, &settings);
        log_roles(source.ids(), &settings);
    }
    let levels = source.levels();
    let resting = link.status().mode == HeadMode::Resting;
    // The radar counts as presence while it is on.
    inputs.sense(now, links.show.track.presence());
    inputs.update(&settings, now, levels, resting);
    let mut full = false;
    while let Some(action) = inputs.pending(&settings) {
        if links.commands.try_submit(action).is_err() {
            full = true;
            break;
        }
        inputs.sent();
    }
    let status = inputs.status(&settings);
    link.publish_inputs(status);
    if status.active != shown.active {
        shown.active = status.active;
        log::info!(
            "inputs: active {=u8:#06b} (bit 0: the first input)",
            shown.active
        );
    }
    if inputs.lost() != shown.lost {
        shown.lost = inputs.lost();
        log::warn!(
            "inputs: {=u32} action(s) lost so far: the command queue stayed full",
            shown.lost
        );
    }
    let deadline = if full {
        Some(wake.now + RETRY)
    } else {
        inputs
            .deadline(&settings)
            .map(|at| Instant::from_micros(at.0))
    };
    (levels, settings.watched(), deadline)
}

/// Logs the role of each of the inputs numbered `ids`.
fn log_roles(ids: InputIds, settings: &InputSettings) {
    for (&n, role) in ids.as_slice().iter().zip(settings.roles.iter()) {
        log::info!("input {=u8}: {=str}", n, role.word());
    }
}

#[cfg(test)]
mod tests;
