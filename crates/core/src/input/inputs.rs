//! Every input's debouncer, what its edges do, and the rest timer.
//!
//! The input task tells [`Inputs::update`] the levels of its inputs
//! whenever one may have changed and at the deadline [`Inputs::deadline`]
//! asks for, with whether the head rests (as the frame task last said) and
//! the settings in effect (the state machine keeps no copy of them: the
//! console's link holds them). Out come actions for the frame task's
//! queue, oldest first ([`Inputs::pending`], [`Inputs::sent`]): nothing is
//! lost while the queue is full for a while (the input task retries), and
//! what does not fit the outbox is counted ([`Inputs::lost`]).
//!
//! - A button's press (its debounced falling edge) runs its action, unless
//!   it comes within [`BUTTON_HOLD_OFF`] of the last press it ran.
//! - A presence input's rising edge wakes a resting head: a `wake`, with
//!   the input's direction for a glance unless the last glance was less
//!   than [`GLANCE_HOLD_OFF`] ago. A head that is awake glances only.
//! - The rest timer: with at least one presence input and none active,
//!   the head rests ([`Action::Rest`]) once nobody has been there for
//!   [`RestAfter`]. The timer starts again when presence ends, when the
//!   head wakes (by a sensor, a button or the console), and when the
//!   settings change.

use crate::command::Action;

use super::{BUTTON_HOLD_OFF, Debouncer, GLANCE_HOLD_OFF, InputRole, InputSettings, SLOTS};

/// A moment, in µs since the board started.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Micros(pub u64);

impl Micros {
    /// `ms` milliseconds later.
    #[must_use]
    pub const fn after_ms(self, ms: u32) -> Self {
        Self(self.0.saturating_add(ms as u64 * 1000))
    }

    /// Whether at least `ms` milliseconds passed from `since` to `self`.
    #[must_use]
    pub const fn passed(self, since: Self, ms: u32) -> bool {
        self.0.saturating_sub(since.0) >= ms as u64 * 1000
    }
}

/// Actions the outbox holds at most: an edge of every input and a rest,
/// should they come at once while the queue is full.
pub const OUTBOX: usize = SLOTS + 1;

/// The inputs as `status` and `input <n>` show them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InputStatus {
    /// Bit `i`: input `i`'s debounced level is high.
    pub high: u8,
    /// Bit `i`: input `i` is active (a button pressed, someone there).
    pub active: u8,
}

impl InputStatus {
    /// Whether input `i` is active.
    #[must_use]
    pub const fn is_active(&self, i: usize) -> bool {
        i < 8 && self.active & (1 << i) != 0
    }

    /// Whether input `i`'s level is high.
    #[must_use]
    pub const fn is_high(&self, i: usize) -> bool {
        i < 8 && self.high & (1 << i) != 0
    }
}

/// A time that never comes (no glance yet; someone there).
const NEVER: Micros = Micros(u64::MAX);

/// What an edge asks for, until it is sent: kept small (the action of a
/// button is its settings').
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pending {
    /// Input `i`'s button action.
    Button(u8),
    /// A wake, with a glance's direction.
    Wake(Option<crate::units::Angle>),
    /// A rest.
    Rest,
}

/// A role's kind: 0 off, 1 button, 2 presence (a new action or direction
/// is the same kind: the input goes on as it was).
const fn kind_of(role: &InputRole) -> u8 {
    match role {
        InputRole::Off => 0,
        InputRole::Button(_) => 1,
        InputRole::Presence { .. } => 2,
    }
}

/// The inputs' state; see the [module docs](self).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Inputs {
    /// Each input's kind of role as of the last settings (see `kind`): a
    /// change of kind starts the input afresh.
    kinds: [u8; SLOTS],
    debouncers: [Debouncer; SLOTS],
    /// When each button last ran its action (bit `i` of `pressed`: ever).
    presses: [Micros; SLOTS],
    pressed: u8,
    /// When the last glance was ([`NEVER`] before the first).
    last_glance: Micros,
    /// Since when no presence input is active ([`NEVER`]: one is).
    empty_since: Micros,
    /// The rest for this stretch without presence is sent (or the head
    /// rests already).
    rest_sent: bool,
    /// The head rested at the last update.
    was_resting: bool,
    /// When the last update was.
    now: Micros,
    /// What is not sent yet: `outbox[first..first + waiting]`, round.
    outbox: [Pending; OUTBOX],
    first: u8,
    waiting: u8,
    lost: u32,
    /// The radar as presence (see [`Inputs::sense`]): whether it counts,
    /// its count of sightings with somebody, when one last came, and
    /// whether presence began since the last update.
    radar: Radar,
}

/// The radar as presence: whether it counts (`None`: off), its count of
/// sightings with somebody, when one last came, and whether presence
/// began since the last update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Radar {
    seen: Option<u32>,
    last: Micros,
    rose: bool,
}

/// How long the radar's presence lasts after the last sighting with
/// somebody in it: a person standing still can drop out of a few of its
/// frames.
pub const RADAR_HOLD_MS: u32 = 3000;
/// How often the input task looks at the radar while it counts, ms.
pub const RADAR_POLL_MS: u32 = 250;

impl Inputs {
    /// Inputs with `settings`, starting at `now`.
    #[must_use]
    pub fn new(settings: &InputSettings, now: Micros) -> Self {
        let mut inputs = Self {
            kinds: [u8::MAX; SLOTS],
            debouncers: [Debouncer::new(); SLOTS],
            presses: [Micros(0); SLOTS],
            pressed: 0,
            last_glance: NEVER,
            empty_since: now,
            rest_sent: false,
            was_resting: false,
            now,
            outbox: [Pending::Rest; OUTBOX],
            first: 0,
            waiting: 0,
            lost: 0,
            radar: Radar {
                seen: None,
                last: NEVER,
                rose: false,
            },
        };
        inputs.configure(settings, now);
        inputs
    }

    /// New settings from `now` on: an input whose role changed starts
    /// afresh (its level as it is, no edge), and the rest timer starts
    /// again.
    pub fn configure(&mut self, settings: &InputSettings, now: Micros) {
        for (i, role) in settings.roles.iter().enumerate() {
            let (Some(kind), Some(debouncer)) = (self.kinds.get_mut(i), self.debouncers.get_mut(i))
            else {
                continue;
            };
            if *kind != kind_of(role) {
                *kind = kind_of(role);
                *debouncer = Debouncer::new();
                self.pressed &= !(1 << i);
            }
        }
        self.rest_sent = false;
        if self.empty_since != NEVER {
            self.empty_since = now;
        }
    }

    /// The radar at `now`, before [`update`](Self::update): `seen`, its
    /// count of sightings with somebody in them (`TrackLink::presence`),
    /// or `None` while it does not count (`radar off`). A change of the
    /// count is somebody there; presence lasts [`RADAR_HOLD_MS`] after the
    /// last one, and its start wakes a resting head (no glance: the
    /// tracker turns the head to the person).
    pub fn sense(&mut self, now: Micros, seen: Option<u32>) {
        let Some(seen) = seen else {
            self.radar.seen = None;
            self.radar.last = NEVER;
            return;
        };
        let Some(before) = self.radar.seen.replace(seen) else {
            // Switched on: the count so far is no one new.
            return;
        };
        if seen != before {
            if !self.radar_present(now) {
                self.radar.rose = true;
            }
            self.radar.last = now;
        }
    }

    /// Whether the radar saw somebody within [`RADAR_HOLD_MS`] of `now`.
    fn radar_present(&self, now: Micros) -> bool {
        self.radar.seen.is_some()
            && self.radar.last != NEVER
            && !now.passed(self.radar.last, RADAR_HOLD_MS)
    }

    /// The inputs' levels at `now` (bit `i`: input `i` high), with whether
    /// the head rests, under `settings`.
    #[inline(never)]
    pub fn update(&mut self, settings: &InputSettings, now: Micros, levels: u8, resting: bool) {
        self.now = now;
        if self.was_resting && !resting && self.empty_since != NEVER {
            // Woken, by whatever: nobody is there for a new stretch.
            self.empty_since = now;
        }
        if self.was_resting != resting {
            self.rest_sent = resting;
        }
        self.was_resting = resting;
        let mut woken = false;
        for (i, role) in settings.roles.iter().enumerate() {
            let (Some(debouncer), Some(rule)) = (self.debouncers.get_mut(i), role.debounce())
            else {
                continue;
            };
            let Some(edge) = debouncer.update(now, levels & (1 << i) != 0, rule) else {
                continue;
            };
            if edge != role.active_high() {
                continue;
            }
            match *role {
                InputRole::Button(_) => self.press(i, now),
                InputRole::Presence { toward } => {
                    let glance = toward.filter(|_| {
                        self.last_glance == NEVER || now.passed(self.last_glance, GLANCE_HOLD_OFF.0)
                    });
                    if glance.is_some() {
                        self.last_glance = now;
                    }
                    if glance.is_some() || (resting && !woken) {
                        self.push(Pending::Wake(glance));
                        woken = true;
                    }
                }
                InputRole::Off => {}
            }
        }
        if core::mem::take(&mut self.radar.rose) && resting && !woken {
            self.push(Pending::Wake(None));
        }
        if self.present(settings) {
            self.empty_since = NEVER;
            self.rest_sent = resting;
        } else if self.empty_since == NEVER {
            self.empty_since = now;
        }
        if let Some(due) = self.rest_due(settings)
            && now >= due
        {
            self.push(Pending::Rest);
            self.rest_sent = true;
        }
    }

    /// A button's press at `now`.
    fn press(&mut self, i: usize, now: Micros) {
        let Some(last) = self.presses.get_mut(i) else {
            return;
        };
        if self.pressed & (1 << i) != 0 && !now.passed(*last, BUTTON_HOLD_OFF.0) {
            return;
        }
        *last = now;
        self.pressed |= 1 << i;
        self.push(Pending::Button(i as u8));
    }

    /// Whether a presence input is active, or the radar sees somebody.
    fn present(&self, settings: &InputSettings) -> bool {
        self.radar_present(self.now)
            || settings
                .roles
                .iter()
                .zip(&self.debouncers)
                .any(|(role, d)| role.is_presence() && d.level())
    }

    /// When the rest is due, if it is to come.
    fn rest_due(&self, settings: &InputSettings) -> Option<Micros> {
        if self.rest_sent || !(settings.presence() || self.radar.seen.is_some()) {
            return None;
        }
        let after = settings.rest_after.micros()?;
        if self.empty_since == NEVER {
            return None;
        }
        Some(Micros(self.empty_since.0.saturating_add(after)))
    }

    /// When to update again without an edge (a level to confirm, the rest
    /// timer), if at all. Once the rest is sent, while presence inputs are
    /// configured, once a second: the head seen resting, and then a wake
    /// from elsewhere, which starts the rest timer again.
    #[must_use]
    pub fn deadline(&self, settings: &InputSettings) -> Option<Micros> {
        let mut soonest = self.rest_due(settings);
        for (d, role) in self.debouncers.iter().zip(&settings.roles) {
            if let Some(due) = role.debounce().and_then(|rule| d.deadline(rule)) {
                soonest = Some(soonest.map_or(due, |s| s.min(due)));
            }
        }
        if self.radar.seen.is_some() {
            let poll = self.now.after_ms(RADAR_POLL_MS);
            soonest = Some(soonest.map_or(poll, |s| s.min(poll)));
        }
        if (self.was_resting || self.rest_sent) && settings.presence() {
            let poll = self.now.after_ms(1000);
            soonest = Some(soonest.map_or(poll, |s| s.min(poll)));
        }
        soonest
    }

    /// The inputs as `status` shows them, under `settings`.
    #[must_use]
    pub fn status(&self, settings: &InputSettings) -> InputStatus {
        let mut status = InputStatus::default();
        for (i, (role, d)) in settings.roles.iter().zip(&self.debouncers).enumerate() {
            if matches!(role, InputRole::Off) {
                continue;
            }
            if d.level() {
                status.high |= 1 << i;
            }
            if d.level() == role.active_high() {
                status.active |= 1 << i;
            }
        }
        status
    }

    fn push(&mut self, action: Pending) {
        let n = usize::from(self.waiting);
        if n >= OUTBOX {
            self.lost = self.lost.saturating_add(1);
            return;
        }
        let at = (usize::from(self.first) + n) % OUTBOX;
        if let Some(slot) = self.outbox.get_mut(at) {
            *slot = action;
            self.waiting += 1;
        }
    }

    /// The oldest action not sent yet, with `settings` (a button's action
    /// is taken from them when it is sent). Something a change of settings
    /// made void (a button that is one no more) is dropped.
    pub fn pending(&mut self, settings: &InputSettings) -> Option<Action> {
        while self.waiting > 0 {
            let action = match self.outbox.get(usize::from(self.first)) {
                Some(Pending::Rest) => Some(Action::Rest),
                Some(Pending::Wake(toward)) => Some(Action::Wake { toward: *toward }),
                Some(Pending::Button(i)) => match settings.roles.get(usize::from(*i)) {
                    Some(InputRole::Button(action)) => Some(*action),
                    _ => None,
                },
                None => None,
            };
            if action.is_some() {
                return action;
            }
            self.sent();
        }
        None
    }

    /// The oldest action was sent: the next one's turn.
    pub fn sent(&mut self) {
        if self.waiting > 0 {
            self.waiting -= 1;
            self.first = ((usize::from(self.first) + 1) % OUTBOX) as u8;
        }
    }

    /// Actions that did not fit the outbox (the queue stayed full), so far.
    #[must_use]
    pub const fn lost(&self) -> u32 {
        self.lost
    }
}
