//! The service's radar, tracking and seed commands: `radar [on|off]`,
//! `track [on|off|height|mount|prefer]`, `seed [board|paper|<n>|random]`,
//! and their words in `status`.

use super::{ConsoleService, text};
use crate::command::{SeedChoice, TrackSetting};
use crate::console::reply::{ErrorCode, Reply};
use crate::seed::{BoardId, Seeding, Shown};
use crate::settings::{Settings, SettingsSource, SettingsStorage};
use crate::text::Arg::{Int, Str, Uint};
use crate::text::Text;

impl<S: SettingsStorage, const N: usize> ConsoleService<'_, S, N> {
    /// The service on a board whose unique id is `id` (the seeds of
    /// `seed board`).
    #[must_use]
    pub fn with_board(mut self, id: BoardId) -> Self {
        self.board = id;
        self
    }

    /// The board's id, as the boot gave it.
    #[must_use]
    pub const fn board(&self) -> BoardId {
        self.board
    }

    /// `radar`: the receiver's counters (`err unavailable` on a board
    /// without a radar); `radar on|off`, a setting kept and saved on any
    /// board, as `dmx on|off` is.
    pub(super) fn radar(&mut self, on: Option<bool>, reply: &mut Reply<'_>) {
        if let Some(on) = on {
            self.settings.track.radar = on;
            self.push_track();
            return;
        }
        if !self.parts.radar {
            text(reply.err(ErrorCode::Unavailable)).str("this board has no radar");
            return;
        }
        let received = self.show.map(|s| s.track.received()).unwrap_or_default();
        text(reply.ok()).fill(
            "radar={} frames={} bad={} targets={}",
            &[
                Str(if self.settings.track.radar {
                    "on"
                } else {
                    "off"
                }),
                Uint(received.counters.good.into()),
                Uint(received.counters.bad.into()),
                Uint(received.sighting.count().into()),
            ],
        );
    }

    /// `track`: the settings; `track on|off|height|mount|prefer …`.
    pub(super) fn track(&mut self, setting: Option<TrackSetting>, reply: &mut Reply<'_>) {
        let t = &mut self.settings.track;
        match setting {
            None => {
                text(reply.ok()).fill(
                    "track={} height={} mount={} prefer={}",
                    &[
                        Str(if t.gaze { "on" } else { "off" }),
                        Int(t.height.0.into()),
                        Int(t.mount.millidegrees().into()),
                        Str(t.prefer.word()),
                    ],
                );
                return;
            }
            Some(TrackSetting::Gaze(on)) => t.gaze = on,
            Some(TrackSetting::Height(mm)) => t.height = mm,
            Some(TrackSetting::Mount(yaw)) => t.mount = yaw,
            Some(TrackSetting::Prefer(p)) => t.prefer = p,
        }
        self.push_track();
    }

    /// The tracking settings in effect, through the link.
    fn push_track(&mut self) {
        if let Some(show) = self.show {
            show.track.set(self.settings.track);
        }
        self.source = SettingsSource::Changed;
    }

    /// `seed …`: the next loop set is drawn from the new seeds.
    pub(super) fn seed(&mut self, choice: SeedChoice, reply: &mut Reply<'_>) {
        match choice {
            SeedChoice::Board => self.settings.seeding = Seeding::Board,
            SeedChoice::Paper => self.settings.seeding = Seeding::Paper,
            SeedChoice::Value(n) => self.choose(n),
            SeedChoice::Random => {
                // xorshift32, stirred with the frame count.
                let mut x = self.entropy ^ (self.link.status().frame as u32);
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                self.entropy = x | 1;
                self.choose(x);
            }
        }
        self.link.reseed(self.settings.idle_seeds(self.board));
        self.source = SettingsSource::Changed;
        self.show_seed(text(reply.ok()));
    }

    fn choose(&mut self, n: u32) {
        self.settings.seeding = Seeding::Chosen;
        self.settings.seeds = Settings::seeds_from(n);
    }

    /// `seed=…` as `seed` and `status` show it: `board:<n>` (`board:none`
    /// on a board without an id: the paper's seeds), `paper`, `<n>`.
    pub(super) fn show_seed(&self, out: &mut dyn Text) {
        out.str("seed=");
        match self.settings.shown_seed(self.board) {
            Shown::Board(Some(n)) => out.str("board:").u64(n.into()),
            Shown::Board(None) => out.str("board:none"),
            Shown::Paper => out.str("paper"),
            Shown::Value(n) => out.u64(n.into()),
            Shown::Three([p, r, y]) => out.fill(
                "{},{},{}",
                &[Uint(p.into()), Uint(r.into()), Uint(y.into())],
            ),
        };
    }

    /// ` seed=board|paper|<n>` for `status` (short: `seed` alone gives the
    /// board's `n`).
    pub(super) fn status_track(&self, out: &mut dyn Text) {
        out.str(" seed=");
        match self.settings.shown_seed(self.board) {
            Shown::Board(_) => out.str("board"),
            Shown::Paper => out.str("paper"),
            Shown::Value(n) => out.u64(n.into()),
            Shown::Three(_) => out.str("custom"),
        };
    }
}
