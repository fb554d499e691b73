//! The inputs' settings: each input's role, and when the head rests.

pub use crate::command::{MAX_REST_AFTER, RestAfter};

use super::{InputRole, SLOTS};

impl RestAfter {
    /// `seconds`, if in `1..=MAX_REST_AFTER`.
    #[must_use]
    pub const fn seconds(seconds: u32) -> Option<Self> {
        if seconds >= 1 && seconds <= MAX_REST_AFTER {
            Some(Self::Seconds(seconds))
        } else {
            None
        }
    }

    /// The time in µs, if ever.
    #[must_use]
    pub const fn micros(&self) -> Option<u64> {
        match self {
            Self::Never => None,
            Self::Seconds(s) => Some(*s as u64 * 1_000_000),
        }
    }
}

/// Each input's role and the rest timer: what the input task needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InputSettings {
    /// The inputs' roles by slot (see [`InputIds`](super::InputIds)): a
    /// board with fewer inputs keeps the other roles, unused.
    pub roles: [InputRole; SLOTS],
    /// When the head rests (with at least one presence input).
    pub rest_after: RestAfter,
}

impl InputSettings {
    /// Every input off (the head behaves as without inputs), rest after
    /// 2 minutes without presence once a presence input is configured.
    pub const DEFAULT: Self = Self {
        roles: [InputRole::Off; SLOTS],
        rest_after: RestAfter::Seconds(120),
    };

    /// Whether any input is a presence sensor (the head may rest).
    #[must_use]
    pub fn presence(&self) -> bool {
        self.roles.iter().any(InputRole::is_presence)
    }

    /// The inputs a source should watch for a change: every input that is
    /// not off (bit `i`).
    #[must_use]
    pub fn watched(&self) -> u8 {
        self.roles
            .iter()
            .enumerate()
            .filter(|(_, role)| !matches!(role, InputRole::Off))
            .fold(0, |bits, (i, _)| bits | (1 << i))
    }
}

impl Default for InputSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}
