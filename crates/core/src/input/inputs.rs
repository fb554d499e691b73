//! Every input's debouncer, what its edges do, and the rest timer.
//!
//! The input task tells [`Inputs::update`] the levels of its inputs
//! whenever one may have changed and at the deadline [`Inputs::deadline`]
//! asks for, with whether the head rests (as the frame task last said).
//! Out come actions for the frame task's queue, oldest first
//! ([`Inputs::pending`], [`Inputs::sent`]): nothing is lost while the queue
//! is full for a while (the input task retries), and what does not fit
//! the outbox is counted ([`Inputs::lost`]).
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

use super::{BUTTON_HOLD_OFF, Debouncer, GLANCE_HOLD_OFF, INPUTS, InputRole, InputSettings};

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

/// Actions the outbox holds at most: more than a burst of edges makes.
pub const OUTBOX: usize = 6;

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

/// The inputs' state; see the [module docs](self).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Inputs {
    settings: InputSettings,
    debouncers: [Debouncer; INPUTS],
    /// When each button last ran its action.
    pressed: [Option<Micros>; INPUTS],
    last_glance: Option<Micros>,
    /// Since when no presence input is active (`None`: one is).
    empty_since: Option<Micros>,
    /// The rest for this stretch without presence is sent (or the head
    /// rests already).
    rest_sent: bool,
    /// The head rested at the last update.
    was_resting: bool,
    /// When the last update was.
    now: Micros,
    outbox: [Option<Action>; OUTBOX],
    lost: u32,
}

impl Inputs {
    /// Inputs with `settings`, starting at `now`.
    #[must_use]
    pub fn new(settings: &InputSettings, now: Micros) -> Self {
        let mut inputs = Self {
            settings: *settings,
            debouncers: [Debouncer::new(0); INPUTS],
            pressed: [None; INPUTS],
            last_glance: None,
            empty_since: Some(now),
            rest_sent: false,
            was_resting: false,
            now,
            outbox: [None; OUTBOX],
            lost: 0,
        };
        for (i, role) in settings.roles.iter().enumerate() {
            inputs.reset(i, role);
        }
        inputs
    }

    /// The settings in use.
    #[must_use]
    pub const fn settings(&self) -> &InputSettings {
        &self.settings
    }

    /// New settings from `now` on: an input whose role changed starts
    /// afresh (its level as it is, no edge), and the rest timer starts
    /// again.
    pub fn configure(&mut self, settings: &InputSettings, now: Micros) {
        for (i, (new, old)) in settings.roles.iter().zip(self.settings.roles).enumerate() {
            if *new != old {
                self.reset(i, new);
            }
        }
        self.settings = *settings;
        self.rest_sent = false;
        if self.empty_since.is_some() {
            self.empty_since = Some(now);
        }
    }

    fn reset(&mut self, i: usize, role: &InputRole) {
        let hold = role.debounce().map_or(0, |ms| u64::from(ms.0) * 1000);
        if let Some(d) = self.debouncers.get_mut(i) {
            *d = Debouncer::new(hold);
        }
        if let Some(p) = self.pressed.get_mut(i) {
            *p = None;
        }
    }

    /// The inputs' levels at `now` (bit `i`: input `i` high), with whether
    /// the head rests.
    pub fn update(&mut self, now: Micros, levels: u8, resting: bool) {
        self.now = now;
        if self.was_resting && !resting && self.empty_since.is_some() {
            // Woken, by whatever: nobody is there for a new stretch.
            self.empty_since = Some(now);
        }
        if self.was_resting != resting {
            self.rest_sent = resting;
        }
        self.was_resting = resting;
        let mut woken = false;
        let roles = self.settings.roles;
        for (i, role) in roles.iter().enumerate() {
            let Some(debouncer) = self.debouncers.get_mut(i) else {
                continue;
            };
            if matches!(role, InputRole::Off) {
                continue;
            }
            let Some(edge) = debouncer.update(now, levels & (1 << i) != 0) else {
                continue;
            };
            if edge != role.active_high() {
                continue;
            }
            match *role {
                InputRole::Button(action) => self.press(i, now, action),
                InputRole::Presence { toward } => {
                    let glance = toward.filter(|_| {
                        self.last_glance
                            .is_none_or(|at| now.passed(at, GLANCE_HOLD_OFF.0))
                    });
                    if glance.is_some() {
                        self.last_glance = Some(now);
                    }
                    if glance.is_some() || (resting && !woken) {
                        self.push(Action::Wake { toward: glance });
                        woken = true;
                    }
                }
                InputRole::Off => {}
            }
        }
        if self.present() {
            self.empty_since = None;
            self.rest_sent = resting;
        } else if self.empty_since.is_none() {
            self.empty_since = Some(now);
        }
        if let Some(due) = self.rest_due()
            && now >= due
        {
            self.push(Action::Rest);
            self.rest_sent = true;
        }
    }

    /// A button's press at `now`.
    fn press(&mut self, i: usize, now: Micros, action: Action) {
        let Some(last) = self.pressed.get_mut(i) else {
            return;
        };
        if last.is_some_and(|at| !now.passed(at, BUTTON_HOLD_OFF.0)) {
            return;
        }
        *last = Some(now);
        self.push(action);
    }

    /// Whether a presence input is active.
    fn present(&self) -> bool {
        self.settings
            .roles
            .iter()
            .zip(&self.debouncers)
            .any(|(role, d)| role.is_presence() && d.level())
    }

    /// When the rest is due, if it is to come.
    fn rest_due(&self) -> Option<Micros> {
        if self.rest_sent || !self.settings.presence() {
            return None;
        }
        let after = self.settings.rest_after.micros()?;
        let since = self.empty_since?;
        Some(Micros(since.0.saturating_add(after)))
    }

    /// When to update again without an edge (a level to confirm, the rest
    /// timer), if at all. Once the rest is sent, while presence inputs are
    /// configured, once a second: the head seen resting, and then a wake
    /// from elsewhere, which starts the rest timer again.
    #[must_use]
    pub fn deadline(&self) -> Option<Micros> {
        let mut soonest = self.rest_due();
        for d in &self.debouncers {
            if let Some(due) = d.deadline() {
                soonest = Some(soonest.map_or(due, |s| s.min(due)));
            }
        }
        if (self.was_resting || self.rest_sent) && self.settings.presence() {
            let poll = self.now.after_ms(1000);
            soonest = Some(soonest.map_or(poll, |s| s.min(poll)));
        }
        soonest
    }

    /// Which inputs the source should watch for a change: every input that
    /// is not off (bit `i`).
    #[must_use]
    pub fn watched(&self) -> u8 {
        self.settings
            .roles
            .iter()
            .enumerate()
            .filter(|(_, role)| !matches!(role, InputRole::Off))
            .fold(0, |bits, (i, _)| bits | (1 << i))
    }

    /// The inputs as `status` shows them.
    #[must_use]
    pub fn status(&self) -> InputStatus {
        let mut status = InputStatus::default();
        for (i, (role, d)) in self.settings.roles.iter().zip(&self.debouncers).enumerate() {
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

    fn push(&mut self, action: Action) {
        match self.outbox.iter_mut().find(|slot| slot.is_none()) {
            Some(slot) => *slot = Some(action),
            None => self.lost = self.lost.saturating_add(1),
        }
    }

    /// The oldest action not sent yet.
    #[must_use]
    pub fn pending(&self) -> Option<Action> {
        self.outbox.first().copied().flatten()
    }

    /// The oldest action was sent: the next one's turn.
    pub fn sent(&mut self) {
        self.outbox.rotate_left(1);
        if let Some(last) = self.outbox.last_mut() {
            *last = None;
        }
    }

    /// Actions that did not fit the outbox (the queue stayed full), so far.
    #[must_use]
    pub const fn lost(&self) -> u32 {
        self.lost
    }
}
