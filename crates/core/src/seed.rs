//! Where the idle motion's seeds come from: the board's unique id (the
//! default, so that heads flashed from one image never move in step), the
//! paper's Table 2 seeds, or seeds a person chose (`seed <n>`).
//!
//! # The board's seeds
//!
//! The board reads its unique id once at boot (the RP2040's flash unique
//! id, the RP2350's chip id: the board layer's business) and hands it to
//! the core as a [`BoardId`]. The seed `n` is the id folded to 32 bits
//! through the `SplitMix64` finaliser (every bit of the id moves every bit of
//! `n`, so ids that differ in one digit give unrelated motion), and the
//! three seeds are those `seed <n>` gives ([`Settings::seeds_from`]): a
//! person who likes a head's motion can give another head the same with
//! `seed <n>`, `n` as `status` shows it (`seed=board:<n>`).
//!
//! An id of all zeros or all ones is no id (an erased or unreadable
//! flash reads so): such a board, and one that cannot read an id, plays
//! the paper's seeds, as every board did before. A seed whose walk the
//! motion rejects as flat ([`MotionError::Degenerate`]) cannot stop the
//! head: the loop generator moves on to the next seeds, as it does for
//! any set (`idle::LoopStream`); `host-tests/tests/seeds.rs` generates the
//! loops of hundreds of ids and finds none.
//!
//! [`Settings::seeds_from`]: crate::settings::Settings::seeds_from
//! [`MotionError::Degenerate`]: crate::motion::MotionError::Degenerate

use crate::motion::DEFAULT_HEAD;

/// The board's unique id, as read at boot (see the [module docs](self)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoardId(pub u64);

impl BoardId {
    /// No id: the board could not read one.
    pub const NONE: Self = Self(0);

    /// The seed `n` of this id, `None` for no id.
    #[must_use]
    pub const fn seed(self) -> Option<u32> {
        if self.0 == 0 || self.0 == u64::MAX {
            return None;
        }
        // SplitMix64's finaliser (Steele, Lea, Flood 2014).
        let mut z = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        Some((z ^ (z >> 32)) as u32)
    }
}

/// The paper's Table 2 seeds, `[pitch, roll, yaw]`.
pub const PAPER: [u32; 3] = [
    DEFAULT_HEAD.pitch.seed,
    DEFAULT_HEAD.roll.seed,
    DEFAULT_HEAD.yaw.seed,
];

/// Where the seeds come from (`seed board|paper|<n>|random`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Seeding {
    /// From the board's unique id (the default).
    #[default]
    Board,
    /// The paper's Table 2 seeds.
    Paper,
    /// The settings' own seeds (`seed <n>`, `seed random`).
    Chosen,
}

/// The seed in use as `status` and `seed` show it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    /// `board:<n>`, or `board:none` (the paper's seeds: no id).
    Board(Option<u32>),
    /// `paper`.
    Paper,
    /// `<n>`.
    Value(u32),
    /// Three seeds that no `seed <n>` gives (set by hand in a record).
    Three([u32; 3]),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::Settings;

    #[test]
    fn ids_give_unrelated_seeds_and_no_id_the_papers() {
        assert_eq!(BoardId::NONE.seed(), None);
        assert_eq!(BoardId(u64::MAX).seed(), None);
        let a = BoardId(0xE660_5838_1B23_4A2F).seed().unwrap();
        let b = BoardId(0xE660_5838_1B23_4A2E).seed().unwrap();
        assert_ne!(a, b);
        assert!((a ^ b).count_ones() > 8);
        let s = Settings::DEFAULT;
        assert_eq!(s.seeding, Seeding::Board);
        assert_eq!(s.idle_seeds(BoardId::NONE), PAPER);
        assert_eq!(
            s.idle_seeds(BoardId(7)),
            Settings::seeds_from(BoardId(7).seed().unwrap())
        );
        assert_eq!(Settings::seeding_of_older(PAPER), Seeding::Board);
        assert_eq!(Settings::seeding_of_older([1, 2, 3]), Seeding::Chosen);
    }
}
