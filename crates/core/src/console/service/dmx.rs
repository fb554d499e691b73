//! The console's show commands: `dmx`, `dmx on|off`, `dmx address <n>`,
//! and the `dmx=` word of `status`.

use super::{ConsoleService, text};
use crate::behaviour::ShowLink;
use crate::command::DmxSetting;
use crate::console::reply::{ErrorCode, Reply};
use crate::dmx::Signal;
use crate::settings::{SettingsSource, SettingsStorage};
use crate::text::Arg::{Str, Uint};

impl<'a, S: SettingsStorage, const N: usize> ConsoleService<'a, S, N> {
    /// The service on a board with a show layer: `dmx` commands and
    /// `status`'s `dmx=` go through `show` (which takes the settings' DMX
    /// part now).
    #[must_use]
    pub fn with_show(mut self, show: &'a ShowLink) -> Self {
        show.dmx.set(self.settings.dmx);
        show.track.set(self.settings.track);
        self.show = Some(show);
        self
    }

    /// ` dmx=ok|lost|off` for `status`; nothing on a board without DMX.
    pub(super) fn dmx_status(&self) -> &'static str {
        match self.signal() {
            Some(Signal::Ok) => " dmx=ok",
            Some(Signal::Lost) => " dmx=lost",
            Some(Signal::Off) => " dmx=off",
            None => "",
        }
    }

    /// The DMX signal as `status` and `dmx` report it: `off` as soon as
    /// it is switched off, else as the frame task last judged it; `None`
    /// on a board without a receiver.
    fn signal(&self) -> Option<Signal> {
        let show = self.show.filter(|_| self.parts.dmx)?;
        Some(match (self.settings.dmx.on, show.dmx.signal()) {
            (false, _) => Signal::Off,
            (true, Signal::Ok) => Signal::Ok,
            (true, _) => Signal::Lost,
        })
    }

    pub(super) fn dmx(&mut self, setting: Option<DmxSetting>, reply: &mut Reply<'_>) {
        let Some(setting) = setting else {
            let Some(show) = self.show.filter(|_| self.parts.dmx) else {
                text(reply.err(ErrorCode::Unavailable)).str("this board has no DMX receiver");
                return;
            };
            let c = show.dmx.counters();
            text(reply.ok()).fill(
                "dmx={} address={} good={} short={} long={} start_code={} garbled={}",
                &[
                    Str(self.signal().map_or("off", Signal::as_str)),
                    Uint(self.settings.dmx.address.get().into()),
                    Uint(c.good.into()),
                    Uint(c.short.into()),
                    Uint(c.long.into()),
                    Uint(c.bad_start.into()),
                    Uint(c.garbled.into()),
                ],
            );
            return;
        };
        // A setting like any other, kept and saved also on a board without
        // a receiver.
        match setting {
            DmxSetting::On(on) => self.settings.dmx.on = on,
            DmxSetting::Address(address) => self.settings.dmx.address = address,
        }
        if let Some(show) = self.show {
            show.dmx.set(self.settings.dmx);
        }
        self.source = SettingsSource::Changed;
    }
}
