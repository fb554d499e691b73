//! The seeds a record's [`Seeding`] gives on a board (see [`crate::seed`]).

use crate::seed::{BoardId, PAPER, Seeding, Shown};

use super::Settings;

impl Settings {
    /// The idle motion's seeds on a board of `id`.
    #[must_use]
    pub const fn idle_seeds(&self, id: BoardId) -> [u32; 3] {
        match self.seeding {
            Seeding::Board => match id.seed() {
                Some(n) => Self::seeds_from(n),
                None => PAPER,
            },
            Seeding::Paper => PAPER,
            Seeding::Chosen => self.seeds,
        }
    }

    /// The seed in use, as shown.
    #[must_use]
    pub fn shown_seed(&self, id: BoardId) -> Shown {
        match self.seeding {
            Seeding::Board => Shown::Board(id.seed()),
            Seeding::Paper => Shown::Paper,
            Seeding::Chosen if Self::seeds_from(self.seeds[0]) == self.seeds => {
                Shown::Value(self.seeds[0])
            }
            Seeding::Chosen => Shown::Three(self.seeds),
        }
    }

    /// The seeding of a record saved before seeds had a source: the
    /// paper's seeds, which every board had unless a person chose others,
    /// become the board's; any other seeds were chosen, and are kept.
    #[must_use]
    pub fn seeding_of_older(seeds: [u32; 3]) -> Seeding {
        if seeds == PAPER {
            Seeding::Board
        } else {
            Seeding::Chosen
        }
    }
}
