//! The input task's steps against a scripted source: what reaches the
//! frame task's queue and the console's link, at which wake.

use embassy_time::Instant;
use idle_head_core::Angle;
use idle_head_core::command::{Action, GestureKind, GestureRequest, InputRole};
use idle_head_core::input::{
    BUTTON_DEBOUNCE, BUTTON_HOLD_OFF, InputIds, InputSettings, PRESENCE_DEBOUNCE, Pull, RestAfter,
    SLOTS,
};

use super::{InputSource, RETRY, Shown, Wake, start, step};
use crate::boot::Links;

const NOD: Action = Action::Gesture(GestureRequest::new(GestureKind::Nod));

/// Levels set by the test; the pulls the task set up.
struct Source {
    levels: u8,
    pulls: [Option<Pull>; SLOTS],
}

impl InputSource for Source {
    fn ids(&self) -> InputIds {
        InputIds::new(&[2, 3, 4, 5]).unwrap()
    }

    fn set_pull(&mut self, i: usize, pull: Pull) {
        self.pulls[i] = Some(pull);
    }

    fn levels(&mut self) -> u8 {
        self.levels
    }

    async fn changed(&mut self, _seen: u8, _watched: u8) {
        unreachable!("the steps are driven by the test")
    }
}

/// The input task as `run` drives it, woken by the test at given times.
struct Task {
    links: Box<Links>,
    source: Source,
    inputs: idle_head_core::input::Inputs,
    shown: Shown,
    /// What the last wake returned: levels, watched, deadline.
    last: (u8, u8, Option<Instant>),
}

fn ms(ms: u64) -> Instant {
    Instant::from_millis(ms)
}

impl Task {
    /// The task started at 0 ms on `settings` (the boot's), with the
    /// inputs at `levels`.
    fn new(settings: InputSettings, levels: u8) -> Self {
        let links = Box::new(Links::new());
        links.console.set_inputs(settings);
        let mut source = Source {
            levels,
            pulls: [None; SLOTS],
        };
        let inputs = start(&mut source, &links, ms(0));
        let mut task = Self {
            links,
            source,
            inputs,
            shown: Shown::default(),
            last: (0, 0, None),
        };
        task.wake(0, false);
        task
    }

    /// A wake at `at` ms (`changed`: the settings' signal woke it).
    fn wake(&mut self, at: u64, changed: bool) {
        let wake = Wake {
            changed,
            now: ms(at),
        };
        self.last = step(
            &mut self.source,
            &mut self.inputs,
            &mut self.shown,
            wake,
            &self.links,
        );
    }

    /// The levels become `levels` at `at` ms: the source's change wakes
    /// the task.
    fn set(&mut self, at: u64, levels: u8) {
        self.source.levels = levels;
        self.wake(at, false);
    }

    /// The actions the frame task finds in its queue.
    fn taken(&self) -> Vec<Action> {
        std::iter::from_fn(|| self.links.commands.take()).collect()
    }
}

/// A button on the first input (GP2) that nods, the others off.
fn button() -> InputSettings {
    let mut roles = [InputRole::Off; SLOTS];
    roles[0] = InputRole::Button(NOD);
    InputSettings {
        roles,
        rest_after: RestAfter::Seconds(120),
    }
}

/// A presence sensor on the second input (GP3) toward `deg`.
fn presence(deg: i32) -> InputSettings {
    let mut roles = [InputRole::Off; SLOTS];
    roles[1] = InputRole::Presence {
        toward: Some(Angle::from_degrees(deg)),
    };
    InputSettings {
        roles,
        rest_after: RestAfter::Seconds(120),
    }
}

/// Idle levels of `button()`: pulled up, high.
const RELEASED: u8 = 0b0001;
const PRESSED: u8 = 0b0000;

#[test]
fn the_pulls_follow_the_roles_and_only_configured_inputs_are_watched() {
    let task = Task::new(button(), RELEASED);
    assert_eq!(task.source.pulls[0], Some(Pull::Up));
    assert!(
        task.source.pulls[1..]
            .iter()
            .all(|p| *p == Some(Pull::Down))
    );
    let (levels, watched, _) = task.last;
    assert_eq!(levels, RELEASED);
    assert_eq!(watched, 0b0001);
}

#[test]
fn a_press_acts_once_at_its_leading_edge_and_the_release_does_nothing() {
    let mut task = Task::new(button(), RELEASED);
    assert!(task.taken().is_empty(), "nothing before a press");
    task.set(1000, PRESSED);
    assert_eq!(task.taken(), [NOD], "the press acts at once");
    assert!(task.links.console.inputs().is_active(0));
    // The release, past the debounce and the hold-off.
    let release = 1000 + u64::from(BUTTON_HOLD_OFF.0) + 100;
    task.set(release, RELEASED);
    assert!(task.taken().is_empty(), "the release is no action");
    assert!(!task.links.console.inputs().is_active(0));
}

#[test]
fn bounces_after_a_press_are_one_press() {
    let mut task = Task::new(button(), RELEASED);
    task.set(1000, PRESSED);
    // Contacts bouncing within the debounce time.
    for (i, at) in (1001..1000 + u64::from(BUTTON_DEBOUNCE.0)).enumerate() {
        task.set(at, if i % 2 == 0 { RELEASED } else { PRESSED });
    }
    task.set(1000 + u64::from(BUTTON_DEBOUNCE.0), PRESSED);
    task.wake(1100, false);
    assert_eq!(task.taken(), [NOD]);
    // Released and pressed again after the hold-off: a second press.
    task.set(1500, RELEASED);
    task.set(2000, PRESSED);
    assert_eq!(task.taken(), [NOD]);
}

#[test]
fn a_presence_counts_once_it_has_held_and_the_task_asks_to_wake_then() {
    let mut task = Task::new(presence(30), 0);
    task.set(1000, 0b0010);
    let hold = u64::from(PRESENCE_DEBOUNCE.0);
    let (_, watched, deadline) = task.last;
    assert_eq!(watched, 0b0010);
    assert_eq!(deadline, Some(ms(1000 + hold)), "woken when it has held");
    assert!(!task.links.console.inputs().is_active(1), "not yet");
    assert!(task.taken().is_empty());
    task.wake(1000 + hold, false);
    assert!(task.links.console.inputs().is_active(1));
    // Someone there: the head is woken, glancing toward the sensor.
    assert_eq!(
        task.taken(),
        [Action::Wake {
            toward: Some(Angle::from_degrees(30))
        }]
    );
}

#[test]
fn a_presence_shorter_than_its_debounce_is_nothing() {
    let mut task = Task::new(presence(0), 0);
    task.set(1000, 0b0010);
    task.set(1000 + u64::from(PRESENCE_DEBOUNCE.0) / 2, 0);
    task.wake(1000 + u64::from(PRESENCE_DEBOUNCE.0), false);
    assert!(task.taken().is_empty());
    assert!(!task.links.console.inputs().is_active(1));
}

#[test]
fn a_full_queue_holds_the_action_back_and_retries() {
    let mut task = Task::new(button(), RELEASED);
    let mut queued = 0;
    while task.links.commands.try_submit(Action::Stop).is_ok() {
        queued += 1;
    }
    task.set(1000, PRESSED);
    assert_eq!(task.last.2, Some(ms(1000) + RETRY), "retried soon");
    assert_eq!(task.links.commands.len(), queued);
    // The frame task takes one: the retry sends the press.
    assert_eq!(task.links.commands.take(), Some(Action::Stop));
    task.wake(1000 + RETRY.as_millis(), false);
    let taken = task.taken();
    assert_eq!(taken.last(), Some(&NOD));
    assert_eq!(taken.len(), queued);
    assert_eq!(task.inputs.lost(), 0);
}

#[test]
fn new_settings_from_the_console_take_effect_at_the_next_wake() {
    let mut task = Task::new(InputSettings::DEFAULT, 0);
    assert_eq!(task.last.1, 0, "nothing watched");
    assert_eq!(task.last.2, None, "no deadline: the task sleeps");
    task.links.console.set_inputs(button());
    // The signal woke the task (and `run` took it).
    assert!(task.links.console.take_inputs_changed());
    task.source.levels = RELEASED;
    task.wake(500, true);
    assert_eq!(task.source.pulls[0], Some(Pull::Up));
    assert_eq!(task.last.1, 0b0001);
    task.set(1000, PRESSED);
    assert_eq!(task.taken(), [NOD]);
}

#[test]
fn new_settings_pending_when_something_else_wakes_the_task_take_effect_then() {
    let mut task = Task::new(InputSettings::DEFAULT, RELEASED);
    task.links.console.set_inputs(button());
    // The press woke the task before its wait saw the settings' signal.
    task.set(500, PRESSED);
    assert_eq!(task.source.pulls[0], Some(Pull::Up));
    assert_eq!(task.last.1, 0b0001, "the button is watched");
    assert!(
        !task.links.console.take_inputs_changed(),
        "the change was taken"
    );
    task.set(600, RELEASED);
    task.set(1000, PRESSED);
    assert_eq!(task.taken(), [NOD]);
}

/// Another source than pins: presence announced by messages on a bus
/// (`[input, level]`, from a sensor on another board), one input numbered
/// 40. No pulls: it ignores them.
struct BusPresence {
    present: bool,
}

impl BusPresence {
    const ID: u8 = 40;

    /// A message from the bus: `[input, 0|1]`; others are not for it.
    fn receive(&mut self, message: &[u8]) {
        if let [Self::ID, level @ (0 | 1)] = message {
            self.present = *level == 1;
        }
    }
}

impl InputSource for BusPresence {
    fn ids(&self) -> InputIds {
        InputIds::new(&[Self::ID]).unwrap()
    }

    fn set_pull(&mut self, _: usize, _: Pull) {}

    fn levels(&mut self) -> u8 {
        u8::from(self.present)
    }

    async fn changed(&mut self, seen: u8, watched: u8) {
        if (self.levels() ^ seen) & watched == 0 {
            // The next message wakes the task on a board; here the test does.
            core::future::pending::<()>().await;
        }
    }
}

#[test]
fn presence_from_bus_messages_wakes_and_rests_the_head_as_a_pin_would() {
    let links = Box::new(Links::new());
    let mut roles = [InputRole::Off; SLOTS];
    roles[0] = InputRole::Presence { toward: None };
    links.console.set_inputs(InputSettings {
        roles,
        rest_after: RestAfter::Seconds(1),
    });
    let mut bus = BusPresence { present: false };
    let mut inputs = start(&mut bus, &links, ms(0));
    let mut shown = Shown::default();
    let mut wake = |bus: &mut BusPresence, at: u64| {
        let wake = Wake {
            changed: false,
            now: ms(at),
        };
        step(bus, &mut inputs, &mut shown, wake, &links)
    };
    let taken = |links: &Links| std::iter::from_fn(|| links.commands.take()).collect::<Vec<_>>();
    let (levels, watched, _) = wake(&mut bus, 0);
    assert_eq!((levels, watched), (0, 0b1));
    // A message that is not for it changes nothing; the one that is ends
    // the wait at once.
    bus.receive(&[41, 1]);
    assert_eq!(bus.levels(), 0);
    bus.receive(&[BusPresence::ID, 1]);
    embassy_futures::block_on(bus.changed(levels, watched));
    wake(&mut bus, 100);
    wake(&mut bus, 100 + u64::from(PRESENCE_DEBOUNCE.0));
    assert!(links.console.inputs().is_active(0));
    // Nobody any more: the head rests a second later.
    bus.receive(&[BusPresence::ID, 0]);
    wake(&mut bus, 500);
    let (_, _, deadline) = wake(&mut bus, 500 + u64::from(PRESENCE_DEBOUNCE.0));
    assert!(!links.console.inputs().is_active(0));
    let rest = deadline.expect("the rest timer runs");
    wake(&mut bus, rest.as_millis());
    assert_eq!(taken(&links), [Action::Rest]);
}

/// A resting head, as the frame task reports it.
fn resting(task: &Task) {
    task.links
        .console
        .publish(idle_head_core::console::HeadStatus {
            mode: idle_head_core::console::HeadMode::Resting,
            ..idle_head_core::console::HeadStatus::default()
        });
}

/// A radar frame with somebody in it, through the receiver's link.
fn somebody(task: &Task) {
    use idle_head_core::Millimetres;
    use idle_head_core::track::{Counters, Person, Sighting};
    let mut seen = Sighting::NOBODY;
    seen.people[0] = Some(Person {
        x: Millimetres(0),
        y: Millimetres(1500),
    });
    task.links
        .show
        .track
        .publish(Some(seen), Counters::default());
}

/// Whether a resting head, the radar `on` or off, is woken when the radar
/// sees somebody.
fn woken_by_a_sighting(on: bool) -> bool {
    let mut task = Task::new(InputSettings::DEFAULT, 0);
    let mut settings = task.links.show.track.settings();
    settings.radar = on;
    task.links.show.track.set(settings);
    resting(&task);
    task.wake(100, false);
    somebody(&task);
    task.wake(200, false);
    task.taken()
        .iter()
        .any(|a| matches!(a, Action::Wake { .. }))
}

#[test]
fn the_radar_wakes_a_resting_head_and_only_while_it_is_on() {
    assert!(!woken_by_a_sighting(false), "off: a sighting is nobody");
    assert!(woken_by_a_sighting(true), "a radar sighting wakes the head");
}

#[test]
fn a_button_bound_to_a_look_by_the_console_runs_that_look_at_its_press() {
    use idle_head_core::command::Command;
    let line = b"input 2 button look 0 3000 60 hold=stay";
    let Ok(Command::Input {
        input: 2,
        role: Some(role @ InputRole::Button(look @ Action::Look(_))),
    }) = idle_head_core::console::parse(line)
    else {
        panic!("`input 2 button look 0 3000 60 hold=stay` is a button running a look")
    };
    let mut roles = [InputRole::Off; SLOTS];
    roles[0] = role;
    let settings = InputSettings {
        roles,
        rest_after: RestAfter::Seconds(120),
    };
    let mut task = Task::new(settings, RELEASED);
    assert!(task.taken().is_empty());
    task.set(1000, PRESSED);
    assert_eq!(task.taken(), [look], "the press runs the look at once");
}
