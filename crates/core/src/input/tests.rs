//! The inputs' state machine against scripted levels, driven as the input
//! task drives it: an update at every change of level and at every
//! deadline it asks for.

use super::*;
use crate::command::{Action, GestureKind, GestureRequest};
use crate::units::Angle;

const NOD: Action = Action::Gesture(GestureRequest::new(GestureKind::Nod));

fn settings(roles: [InputRole; SLOTS], rest_after: RestAfter) -> InputSettings {
    InputSettings { roles, rest_after }
}

/// The settings with `role` on the first input (GP2), the others off.
fn first(role: InputRole, rest_after: RestAfter) -> InputSettings {
    let mut roles = [InputRole::Off; SLOTS];
    roles[0] = role;
    settings(roles, rest_after)
}

fn presence(deg: Option<i32>) -> InputRole {
    InputRole::Presence {
        toward: deg.map(Angle::from_degrees),
    }
}

/// A run: levels changing at given times (ms), the head resting from and
/// until given times; every action taken, with its time in ms.
struct Run {
    settings: InputSettings,
    inputs: Inputs,
    levels: u8,
    resting: bool,
    now: u64,
    actions: Vec<(u64, Action)>,
}

impl Run {
    /// Inputs with `settings`, every level at its idle (buttons high).
    fn new(settings: &InputSettings) -> Self {
        let levels = settings
            .roles
            .iter()
            .enumerate()
            .filter(|(_, r)| !r.active_high())
            .fold(0, |b, (i, _)| b | (1 << i));
        let mut inputs = Inputs::new(settings, Micros(0));
        inputs.update(settings, Micros(0), levels, false);
        Self {
            settings: *settings,
            inputs,
            levels,
            resting: false,
            now: 0,
            actions: Vec::new(),
        }
    }

    fn update(&mut self) {
        self.inputs.update(
            &self.settings,
            Micros(self.now * 1000),
            self.levels,
            self.resting,
        );
        while let Some(action) = self.inputs.pending(&self.settings) {
            self.actions.push((self.now, action));
            self.inputs.sent();
            // The frame task: a rest makes the head rest, a wake wakes it.
            match action {
                Action::Rest => self.resting = true,
                Action::Wake { .. } => self.resting = false,
                _ => {}
            }
        }
    }

    /// Runs to `ms`, updating at every deadline on the way.
    fn until(&mut self, ms: u64) {
        while let Some(due) = self.inputs.deadline(&self.settings) {
            let due = due.0.div_ceil(1000);
            if due > ms {
                break;
            }
            self.now = due.max(self.now);
            self.update();
        }
        self.now = ms;
    }

    /// Input `i` to `high` at `ms`.
    fn set(&mut self, ms: u64, i: usize, high: bool) {
        self.until(ms);
        if high {
            self.levels |= 1 << i;
        } else {
            self.levels &= !(1 << i);
        }
        self.update();
    }

    /// The head woken (or put to rest) from elsewhere at `ms`.
    fn head(&mut self, ms: u64, resting: bool) {
        self.until(ms);
        self.resting = resting;
        self.update();
    }
}

#[test]
fn a_press_runs_the_action_once_at_its_edge() {
    let s = first(InputRole::Button(NOD), RestAfter::Never);
    let mut run = Run::new(&s);
    run.set(100, 0, false);
    run.until(10_000);
    // Held for 10 s: one nod, at the press.
    assert_eq!(run.actions, [(100, NOD)]);
    let status = run.inputs.status(&s);
    assert!(status.is_active(0) && !status.is_high(0));
    run.set(10_000, 0, true);
    run.set(10_300, 0, false);
    run.until(11_000);
    assert_eq!(run.actions, [(100, NOD), (10_300, NOD)]);
}

#[test]
fn a_bouncing_press_is_one_press() {
    let s = first(InputRole::Button(NOD), RestAfter::Never);
    let mut run = Run::new(&s);
    // Bounces every 1 ms for 6 ms, then held: one press.
    for k in 0..6 {
        run.set(100 + k, 0, k % 2 == 1);
    }
    run.set(106, 0, false);
    // Bounces again on release, then a second press 50 ms later: within the
    // hold-off, the same press.
    run.set(200, 0, true);
    run.set(212, 0, false);
    run.set(240, 0, true);
    run.until(1000);
    assert_eq!(run.actions, [(100, NOD)]);
    // Chatter alone, for 200 ms: its first touch is a press (a button's
    // press counts at once), the rest is within the hold-off.
    let mut run = Run::new(&s);
    for k in 0..100 {
        run.set(100 + 2 * k, 0, k % 2 == 1);
    }
    run.until(1000);
    assert_eq!(run.actions, [(100, NOD)]);
}

#[test]
fn nobody_there_for_rest_after_rests_the_head_once() {
    let s = first(presence(None), RestAfter::Seconds(5));
    let mut run = Run::new(&s);
    run.until(60_000);
    assert_eq!(run.actions, [(5000, Action::Rest)]);
    // Someone comes: the head wakes (no direction: no glance).
    run.set(60_000, 0, true);
    run.until(61_000);
    assert_eq!(run.actions[1], (60_050, Action::Wake { toward: None }));
    // Present for a minute, then gone: rests 5 s after the level falls.
    run.set(120_000, 0, false);
    run.until(200_000);
    assert_eq!(run.actions[2..], [(125_050, Action::Rest)]);
}

#[test]
fn a_wake_from_elsewhere_starts_the_rest_timer_again() {
    let s = first(presence(None), RestAfter::Seconds(5));
    let mut run = Run::new(&s);
    run.until(6000);
    assert_eq!(run.actions, [(5000, Action::Rest)]);
    // The console wakes it at 20 s: the timer sees it within a second and
    // rests the head 5 s later.
    run.head(20_000, false);
    run.until(40_000);
    assert_eq!(run.actions[1..], [(25_000, Action::Rest)]);
    // Resting by hand, with nobody there: no second rest.
    let mut run = Run::new(&s);
    run.head(1000, true);
    run.until(30_000);
    assert_eq!(run.actions, []);
}

#[test]
fn a_presence_input_stuck_high_keeps_the_head_awake() {
    let s = first(presence(Some(-20)), RestAfter::Seconds(5));
    let mut run = Run::new(&s);
    run.set(1000, 0, true);
    run.until(3_600_000);
    // One glance, never a rest.
    assert_eq!(
        run.actions,
        [(
            1050,
            Action::Wake {
                toward: Some(Angle::from_degrees(-20))
            }
        )]
    );
    assert_eq!(run.inputs.deadline(&s), None);
    // And a sensor already high when configured: present, but no edge.
    let mut run = Run::new(&settings([InputRole::Off; SLOTS], RestAfter::Seconds(5)));
    run.levels = 1;
    run.settings = s;
    run.inputs.configure(&s, Micros(0));
    run.update();
    run.until(60_000);
    assert_eq!(run.actions, []);
}

#[test]
fn glances_are_held_off_and_two_sensors_at_once_glance_to_the_first() {
    let s = settings(
        [
            presence(Some(-20)),
            presence(Some(25)),
            InputRole::Off,
            InputRole::Off,
        ],
        RestAfter::Seconds(30),
    );
    let mut run = Run::new(&s);
    run.until(40_000);
    assert_eq!(run.actions, [(30_000, Action::Rest)]);
    // Both at once: one wake, towards input 2 (the first).
    run.levels = 0b11;
    run.update();
    run.until(41_000);
    let toward = |deg| Action::Wake {
        toward: Some(Angle::from_degrees(deg)),
    };
    assert_eq!(run.actions[1..], [(40_050, toward(-20))]);
    // Gone and back within 10 s: present again, awake, no glance.
    run.set(42_000, 0, false);
    run.set(42_000, 1, false);
    run.set(45_000, 1, true);
    run.until(46_000);
    assert_eq!(run.actions.len(), 2);
    // After 10 s: the other sensor gets its glance, the head awake.
    run.set(47_000, 1, false);
    run.set(51_000, 1, true);
    run.until(52_000);
    assert_eq!(run.actions[2..], [(51_050, toward(25))]);
}

#[test]
fn without_a_presence_input_the_head_never_rests() {
    let s = first(InputRole::Button(Action::Rest), RestAfter::Seconds(1));
    let mut run = Run::new(&s);
    run.until(3_600_000);
    assert_eq!(run.actions, []);
    assert_eq!(run.inputs.deadline(&s), None);
    assert_eq!(s.watched(), 0b0001);
    // A rest button rests it; another press of it changes nothing more.
    run.set(3_600_000, 0, false);
    run.until(3_601_000);
    assert_eq!(run.actions, [(3_600_000, Action::Rest)]);
    // `never`: presence wakes, never rests.
    let s = first(presence(None), RestAfter::Never);
    let mut run = Run::new(&s);
    run.until(3_600_000);
    assert_eq!(run.actions, []);
}

#[test]
fn a_full_outbox_counts_what_it_lost() {
    let s = settings([InputRole::Button(NOD); SLOTS], RestAfter::Never);
    let mut inputs = Inputs::new(&s, Micros(0));
    inputs.update(&s, Micros(0), 0b1111, false);
    let mut t = 0;
    for _ in 0..3 {
        t += 300_000;
        inputs.update(&s, Micros(t), 0, false);
        inputs.update(&s, Micros(t + 5000), 0, false);
        inputs.update(&s, Micros(t + 10_000), 0b1111, false);
        inputs.update(&s, Micros(t + 15_000), 0b1111, false);
    }
    // 12 presses, 5 kept (none sent), 7 counted lost.
    assert_eq!(inputs.lost(), 7);
    let mut sent = 0;
    while inputs.pending(&s).is_some() {
        inputs.sent();
        sent += 1;
    }
    assert_eq!(sent, OUTBOX);
}

/// The radar as presence: somebody seen wakes a resting head (once), keeps
/// it awake, and nobody for the rest time rests it, with no input set.
#[test]
fn the_radar_is_presence_for_rest_and_wake() {
    use crate::command::Action;
    use crate::input::{InputSettings, Inputs, Micros, RADAR_HOLD_MS};
    let settings = InputSettings {
        rest_after: crate::command::RestAfter::Seconds(10),
        ..InputSettings::DEFAULT
    };
    let ms = |t: u64| Micros(t * 1000);
    let mut inputs = Inputs::new(&settings, ms(0));
    inputs.sense(ms(0), Some(5));
    inputs.update(&settings, ms(0), 0, false);
    assert!(
        inputs.deadline(&settings).is_some(),
        "polls while the radar counts"
    );
    // Nobody for 10 s: rest.
    inputs.sense(ms(10_000), Some(5));
    inputs.update(&settings, ms(10_000), 0, false);
    assert_eq!(inputs.pending(&settings), Some(Action::Rest));
    inputs.sent();
    // Somebody: a wake, once.
    inputs.sense(ms(12_000), Some(6));
    inputs.update(&settings, ms(12_000), 0, true);
    assert_eq!(
        inputs.pending(&settings),
        Some(Action::Wake { toward: None })
    );
    inputs.sent();
    inputs.sense(ms(12_100), Some(7));
    inputs.update(&settings, ms(12_100), 0, false);
    assert_eq!(inputs.pending(&settings), None);
    // Still seen 30 s on: no rest while somebody is there.
    for t in (12_200..42_000).step_by(250) {
        inputs.sense(ms(t), Some(t as u32));
        inputs.update(&settings, ms(t), 0, false);
        assert_eq!(inputs.pending(&settings), None, "at {t} ms");
    }
    // Gone: the rest comes 10 s after the hold.
    let gone = 41_950 + u64::from(RADAR_HOLD_MS);
    inputs.sense(ms(gone), Some(41_950));
    inputs.update(&settings, ms(gone), 0, false);
    assert_eq!(inputs.pending(&settings), None);
    inputs.sense(ms(gone + 10_000), Some(41_950));
    inputs.update(&settings, ms(gone + 10_000), 0, false);
    assert_eq!(inputs.pending(&settings), Some(Action::Rest));
    // Off: no rest timer without presence inputs.
    let mut off = Inputs::new(&settings, ms(0));
    off.sense(ms(0), None);
    off.update(&settings, ms(100_000), 0, false);
    assert_eq!(off.pending(&settings), None);
    assert_eq!(off.deadline(&settings), None);
}
