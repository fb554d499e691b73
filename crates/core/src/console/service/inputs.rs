//! The service's trigger inputs, rest, look and idle settings: `input <n> …`,
//! `rest after|pose|relax …`, `look duck …`, `idle` alone, and the inputs
//! in `status`.
//!
//! Each change is checked, put in the settings (kept with `save`) and sent
//! where it takes effect: the roles and the rest timer to the input task,
//! the rest pose, relax and the look's duck to the frame task (both through
//! the [`ConsoleLink`](super::ConsoleLink)), between two of its frames.

use crate::command::{InputRole, RestAfter, RestSetting};
use crate::settings::{SettingsSource, SettingsStorage};
use crate::text::Arg::{Int, Str, Uint};
use crate::text::Text;
use crate::units::{Angle, Percent};

use super::{ConsoleService, ErrorCode, Reply, behaviour_code, text};
use crate::console::ActionLine;

impl<S: SettingsStorage, const N: usize> ConsoleService<'_, S, N> {
    /// The slot of the board's input numbered `input`; else the reply
    /// says which inputs the board has (`err range`), or that it has none
    /// (`err unavailable`).
    fn input_slot(&self, input: u8, reply: &mut Reply<'_>) -> Option<usize> {
        let ids = self.parts.inputs;
        let slot = ids.slot(input);
        if slot.is_none() {
            if ids.is_empty() {
                text(reply.err(ErrorCode::Unavailable)).str("this board has no trigger inputs");
            } else {
                text(reply.err(ErrorCode::Range))
                    .str("this board has no input ")
                    .u64(input.into())
                    .str(": its inputs are ")
                    .with(&ids);
            }
        }
        slot
    }

    /// `input <n>`: `ok input <n> off`, or its level, then its role as
    /// `input <n> <role>` takes it (`button nod 6000`, `presence -20000`).
    #[inline(never)]
    pub(super) fn show_input(&self, input: u8, reply: &mut Reply<'_>) {
        let Some(i) = self.input_slot(input, reply) else {
            return;
        };
        let Some(role) = self.settings.inputs.roles.get(i) else {
            return;
        };
        let out = text(reply.ok());
        out.str("input ").u64(input.into()).str(" ");
        if !matches!(role, InputRole::Off) {
            let status = self.link.inputs();
            out.str("level=")
                .str(if status.is_high(i) { "high" } else { "low" })
                .str(" active=")
                .u64(status.is_active(i).into())
                .str(" ");
        }
        out.str(role.word());
        match role {
            InputRole::Button(action) => {
                out.str(" ").with(&ActionLine(action));
            }
            InputRole::Presence { toward: Some(yaw) } => {
                out.str(" ").i64(yaw.millidegrees().into());
            }
            InputRole::Off | InputRole::Presence { toward: None } => {}
        }
    }

    /// `input <n> off|button …|presence …`: a button's action is checked as
    /// the console checks a motion command; a direction past the yaw
    /// limits is kept, and the glance clamped to them (the reply says
    /// where it goes).
    #[inline(never)]
    pub(super) fn set_input(&mut self, input: u8, role: InputRole, reply: &mut Reply<'_>) {
        let Some(i) = self.input_slot(input, reply) else {
            return;
        };
        match role {
            InputRole::Button(action) => {
                if let Err(e) = self.behaviour.check(&action) {
                    text(reply.err(behaviour_code(&e))).with(&e);
                    return;
                }
            }
            InputRole::Presence { toward: Some(yaw) } => {
                let (inside, clamped) = self.behaviour.offset_within(crate::Axis::Yaw, yaw);
                if clamped {
                    let glance = inside.saturating_add(self.behaviour.neutral_pose()[2]);
                    text(reply.ok()).fill("clamped yaw={}", &[Int(glance.millidegrees().into())]);
                }
            }
            InputRole::Off | InputRole::Presence { toward: None } => {}
        }
        if let Some(slot) = self.settings.inputs.roles.get_mut(i) {
            *slot = role;
        }
        self.link.set_inputs(self.settings.inputs);
        self.source = SettingsSource::Changed;
    }

    /// `rest after|pose|relax …`.
    #[inline(never)]
    pub(super) fn set_rest(&mut self, setting: RestSetting, reply: &mut Reply<'_>) {
        match setting {
            RestSetting::After(after) => {
                self.settings.inputs.rest_after = after;
                self.link.set_inputs(self.settings.inputs);
            }
            RestSetting::Pose(pose) => {
                self.settings.behaviour.rest.pose = pose;
                if self.push_live() {
                    let [p, r, y] = self.behaviour.rest_pose().map(Angle::millidegrees);
                    text(reply.ok()).fill(
                        "clamped pitch={} roll={} yaw={}",
                        &[Int(p.into()), Int(r.into()), Int(y.into())],
                    );
                }
            }
            RestSetting::Relax(on) => {
                self.settings.behaviour.rest.relax = on;
                self.push_live();
            }
        }
        self.source = SettingsSource::Changed;
    }

    /// `rest after`, `rest pose` or `rest relax` alone: `ok rest
    /// after=<s>|never pose=<p>,<r>,<y> relax=on|off`, the pose as set,
    /// then ` clamped=<p>,<r>,<y>` where the head rests if that lies past
    /// the servos' limits.
    #[inline(never)]
    pub(super) fn show_rest(&self, reply: &mut Reply<'_>) {
        let out = text(reply.ok());
        out.str("rest after=");
        match self.settings.inputs.rest_after {
            RestAfter::Never => out.str("never"),
            RestAfter::Seconds(s) => out.u64(s.into()),
        };
        let rest = &self.settings.behaviour.rest;
        let [p, r, y] = rest.pose.map(Angle::millidegrees);
        out.fill(
            " pose={},{},{} relax={}",
            &[
                Int(p.into()),
                Int(r.into()),
                Int(y.into()),
                Str(if rest.relax { "on" } else { "off" }),
            ],
        );
        if self.behaviour.rest_clamped() {
            let [p, r, y] = self.behaviour.rest_pose().map(Angle::millidegrees);
            out.fill(
                " clamped={},{},{}",
                &[Int(p.into()), Int(r.into()), Int(y.into())],
            );
        }
    }

    /// `look duck` alone: `ok look duck=<percent>`.
    #[inline(never)]
    pub(super) fn show_look_duck(&self, reply: &mut Reply<'_>) {
        text(reply.ok())
            .str("look duck=")
            .u64(self.settings.behaviour.gaze.duck.get().into());
    }

    /// `idle` alone: `ok idle=on|off amp=<percent>`, as the last frame
    /// left the mixer (before the first frame: the settings' amplitude,
    /// and on, as the head starts).
    #[inline(never)]
    pub(super) fn show_idle(&self, reply: &mut Reply<'_>) {
        let idle = self.link.status().idle.unwrap_or(crate::console::IdleView {
            on: true,
            amp: self.settings.behaviour.idle.amplitude,
        });
        text(reply.ok()).fill(
            "idle={} amp={}",
            &[
                Str(if idle.on { "on" } else { "off" }),
                Uint(idle.amp.get().into()),
            ],
        );
    }

    /// `look duck <percent>`.
    #[inline(never)]
    pub(super) fn set_look_duck(&mut self, duck: Percent) {
        self.settings.behaviour.gaze.duck = duck;
        self.push_live();
        self.source = SettingsSource::Changed;
    }

    /// Puts the settings' live part (rest pose, relax, the look's duck) in
    /// effect: in the console's checks and, through the link, in the frame
    /// task. Whether the rest pose had to be clamped to the servos' limits.
    fn push_live(&mut self) -> bool {
        let live = self.settings.behaviour.live();
        let clamped = self.behaviour.set_live(&live);
        self.link.set_live(live);
        clamped
    }

    /// The inputs for `status`: `-` for an input that is off, else `b`
    /// (button) or `p` (presence) and `1` if active, `0` if not, in the
    /// order of the board's inputs (the Pico's: GP2 to GP5,
    /// `inputs=b0,p1,-,-`); nothing on a board without inputs.
    #[inline(never)]
    pub(super) fn status_inputs(&self, out: &mut dyn Text) {
        let used = self.parts.inputs.len();
        if used == 0 {
            return;
        }
        let status = self.link.inputs();
        out.str(" inputs=");
        for (i, role) in self.settings.inputs.roles.iter().enumerate().take(used) {
            if i > 0 {
                out.str(",");
            }
            match role {
                InputRole::Off => {
                    out.str("-");
                }
                InputRole::Button(_) => {
                    out.str("b").u64(status.is_active(i).into());
                }
                InputRole::Presence { .. } => {
                    out.str("p").u64(status.is_active(i).into());
                }
            }
        }
    }

    /// Puts the inputs, rest and look settings of the settings just
    /// adopted in effect (sent whether they changed or not: taking them
    /// again changes nothing).
    pub(super) fn adopt_inputs(&self) {
        self.link.set_inputs(self.settings.inputs);
        self.link.set_live(self.settings.behaviour.live());
    }

    /// Why the settings `next` would refuse a button's action with their
    /// behaviour, if one would: `err limit`.
    pub(super) fn inputs_refused(
        &self,
        next: &crate::settings::Settings,
        behaviour: &crate::behaviour::BehaviourParams,
        reply: &mut Reply<'_>,
    ) -> bool {
        let ids = self.parts.inputs;
        match next.check_inputs(behaviour, ids.len()) {
            Ok(()) => false,
            Err((slot, e)) => {
                text(reply.err(ErrorCode::Limit))
                    .str("input ")
                    .u64(ids.id(slot).unwrap_or_default().into())
                    .str(" would go past the new limits: ")
                    .with(&e);
                true
            }
        }
    }
}
