//! A simulated head behind the console service: the frame task's code
//! (queue drain, servo calibrations, the servos' rate and live settings
//! from the link, frame, status) and the input task's (its inputs at their
//! idle levels)
//! on the host, with PWM channels that keep the last duty, and a check of every
//! frame against the servos' limits as they are at that frame.

use std::convert::Infallible;

use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use idle_head_core::behaviour::{
    Applied, BehaviourConfig, BehaviourError, CommandQueue, Head, RestState, ShowLink,
};
use idle_head_core::console::{
    BoardParts, ConsoleLink, ConsoleService, HeadMode, HeadStatus, Outcome, Session, outcome_reply,
    unanswered,
};
use idle_head_core::driver::{DriverConfig, FrameDriver};
use idle_head_core::input::{InputIds, InputSettings, Inputs, Micros};
use idle_head_core::servo::SetPeriod;
use idle_head_core::settings::RamStorage;
use idle_head_core::{Axis, Timestamp};

/// A PWM channel that keeps the last duty (1 µs per count at any rate).
#[derive(Debug)]
pub struct LastDuty(pub u16, u16);

impl Default for LastDuty {
    fn default() -> Self {
        Self(0, 20_000)
    }
}

impl ErrorType for LastDuty {
    type Error = Infallible;
}

impl SetDutyCycle for LastDuty {
    fn max_duty_cycle(&self) -> u16 {
        self.1
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        self.0 = duty;
        Ok(())
    }
}

impl SetPeriod for LastDuty {
    fn set_period(&mut self, period: idle_head_core::Microseconds) -> Result<(), Infallible> {
        self.1 = u16::try_from(period.0).unwrap_or(u16::MAX);
        Ok(())
    }
}

/// Frames the firmware's console waits for an outcome
/// (`idle_head_firmware::console::OUTCOME_FRAMES`).
pub const OUTCOME_FRAMES: u32 = 5;

/// Frames a servo left outside new angle limits may take to come back:
/// the widest span (720°) at the slowest limiter (60 °/s, 600 °/s²) is
/// 12 s; 50 Hz frames.
pub const RETURN_FRAMES: u64 = 13 * 50;

type Idle = crate::rig::Idle;

/// The frame side of a simulated head: what the frame task owns.
pub struct SimFrames {
    head: Head<Idle>,
    driver: FrameDriver<LastDuty>,
    frame: u64,
    /// The next frame's time, µs.
    at: u64,
    /// Frames played.
    pub frames: u64,
    /// Frames with a pulse or an angle outside the servo's limits.
    pub violations: u64,
    /// Calibrations the driver applied.
    pub calibrations: u64,
    /// Of the violations, angles outside the limits past the return time.
    pub outside_after_return: u64,
    /// The frame of each servo's last calibration change.
    changed: [Option<u64>; 3],
    /// Actions the mixer took, and refused.
    pub applied: u64,
    /// Actions the mixer refused when they came to be played.
    pub refused: u64,
    /// Of those, refused for another reason than every layer being busy
    /// (which depends on what plays, and the console cannot know): the
    /// console said `ok` to something the head would not play.
    pub refused_not_busy: u64,
    /// What the last action played started.
    pub last_applied: Option<Applied>,
    /// Refusals whose outcome a waiting reply was finished with
    /// ([`Self::finish`]).
    pub refusals_told: u64,
    /// The input task's state machine, its inputs at their idle levels
    /// (buttons released, nobody there) unless `levels` says otherwise.
    pub inputs: Inputs,
    /// The inputs' levels (bit `i`: input `i` high); `None`: each at its
    /// idle level.
    pub levels: Option<u8>,
}

impl SimFrames {
    /// A head on the built-in configuration.
    #[must_use]
    pub fn new() -> Self {
        let config = DriverConfig::DEFAULT;
        let params = config.build().expect("the default driver");
        let idle = crate::rig::idle(&params, None);
        let behaviour = BehaviourConfig::DEFAULT
            .build(&params)
            .expect("the default behaviour");
        Self {
            head: Head::new(idle, behaviour),
            driver: FrameDriver::new(
                [
                    LastDuty::default(),
                    LastDuty::default(),
                    LastDuty::default(),
                ],
                params,
            ),
            frame: 0,
            at: 0,
            frames: 0,
            violations: 0,
            calibrations: 0,
            outside_after_return: 0,
            changed: [None; 3],
            applied: 0,
            refused: 0,
            refused_not_busy: 0,
            last_applied: None,
            refusals_told: 0,
            inputs: Inputs::new(&InputSettings::DEFAULT, Micros(0)),
            levels: None,
        }
    }

    /// The input task's part, as it would run at this frame: new settings
    /// from `link`, the levels, actions into `queue`, the status published.
    fn inputs<const N: usize>(&mut self, queue: &CommandQueue<N>, link: &ConsoleLink) {
        let now = Micros(self.at);
        let settings = link.input_settings();
        if link.take_inputs_changed() {
            self.inputs.configure(&settings, now);
        }
        let idle = settings
            .roles
            .iter()
            .enumerate()
            .filter(|(_, role)| !role.active_high())
            .fold(0, |bits, (i, _)| bits | (1 << i));
        let resting = self.head.rest_state() == RestState::Resting;
        self.inputs
            .update(&settings, now, self.levels.unwrap_or(idle), resting);
        while let Some(action) = self.inputs.pending(&settings) {
            if queue.try_submit(action).is_err() {
                break;
            }
            self.inputs.sent();
        }
        link.publish_inputs(self.inputs.status(&settings));
    }

    /// Plays one frame as the frame task does: calibrations from `link`,
    /// queued actions, the frame, the status published.
    pub fn frame<const N: usize>(&mut self, queue: &CommandQueue<N>, link: &ConsoleLink) {
        self.inputs(queue, link);
        if let Some(live) = link.take_live() {
            self.head.set_live(&mut self.driver, &live);
        }
        for (axis, cal) in Axis::ALL.iter().zip(link.take_servos()) {
            if let Some(cal) = cal {
                self.head
                    .set_servo(&mut self.driver, *axis, cal)
                    .expect("the service sends only valid calibrations");
                self.calibrations += 1;
                if let Some(at) = self.changed.get_mut(axis.index()) {
                    *at = Some(self.frame);
                }
            }
        }
        let (mut applied, mut refused, mut not_busy) = (0, 0, 0);
        let last = &mut self.last_applied;
        self.head
            .drain_asked(&mut self.driver, queue, |_, asker, outcome| {
                match outcome {
                    Ok(started) => {
                        applied += 1;
                        *last = Some(*started);
                    }
                    Err(e) => {
                        refused += 1;
                        not_busy += u64::from(!matches!(e, BehaviourError::Busy { .. }));
                    }
                }
                // As the frame task does: the port that asked hears it.
                if let Some(asker) = asker {
                    link.answer(asker, *outcome);
                }
            });
        self.applied += applied;
        self.refused += refused;
        self.refused_not_busy += not_busy;
        // A new rate: the outputs from this frame on, the frames after it.
        let retime = link.take_rate().map(|rate| rate.period());
        if let Some(period) = retime {
            self.driver
                .set_pwm_period(period)
                .expect("the service sends only rates the settings take");
        }
        let at = Timestamp(self.at);
        let report = self.head.frame(&mut self.driver, at).report;
        if let Some(period) = retime {
            self.head
                .set_frame_period(&mut self.driver, period)
                .expect("the service sends only rates the settings take");
        }
        let servos = self.driver.params().config().servos;
        for ((s, cal), changed) in report.servos.iter().zip(&servos).zip(&self.changed) {
            // Pulse limits are hard. A new calibration may leave a servo
            // outside its new angle limits: the driver brings it back in
            // through the limiter, within `RETURN_FRAMES`.
            let returning = changed.is_some_and(|at| self.frame <= at + RETURN_FRAMES);
            // Relaxed at rest: no pulse at all (duty 0), not a short one.
            let pulse = s.duty.0 != 0 || s.pulse.0 != 0;
            if (!cal.limits.contains(s.angle) && !returning)
                || (pulse && (s.pulse.0 < cal.min_pulse.0 || s.pulse.0 > cal.max_pulse.0))
            {
                if !cal.limits.contains(s.angle) {
                    self.outside_after_return += 1;
                }
                self.violations += 1;
            }
        }
        let mode = HeadMode::of(
            self.driver.is_stopped(),
            self.driver.is_stopping(),
            self.head.rest_state(),
        );
        let mut status = HeadStatus::of(&report, self.driver.stats(), mode, at);
        status.idle = Some(self.head.idle_view());
        link.publish(status);
        self.frame += 1;
        self.frames += 1;
        self.at += u64::from(self.driver.params().config().frame_period.0);
    }

    /// Plays frames until the frame task's outcome for `port`'s action
    /// with `ticket` is there, at most [`OUTCOME_FRAMES`] of them, as the
    /// firmware's console waits; the outcome, if one came.
    pub fn outcome<const N: usize>(
        &mut self,
        queue: &CommandQueue<N>,
        link: &ConsoleLink,
        port: u8,
        ticket: u8,
    ) -> Option<Outcome> {
        for _ in 0..OUTCOME_FRAMES {
            self.frame(queue, link);
            while let Some(outcome) = link.take_outcome(port) {
                if outcome.ticket == ticket {
                    return Some(outcome);
                }
            }
        }
        None
    }

    /// Finishes the reply `session` waits for, if it waits: frames until
    /// the outcome is there ([`Self::outcome`]), then the firmware's text
    /// for it ([`outcome_reply`], or [`unanswered`]).
    pub fn finish<'s, const N: usize, const L: usize, const R: usize>(
        &mut self,
        session: &'s mut Session<L, R>,
        queue: &CommandQueue<N>,
        link: &ConsoleLink,
        port: u8,
    ) -> Option<&'s [u8]> {
        let ticket = session.waiting()?;
        let outcome = self.outcome(queue, link, port, ticket);
        if outcome.is_some_and(|o| o.result.is_err()) {
            self.refusals_told += 1;
        }
        session.finish(|reply| match outcome {
            Some(outcome) => outcome_reply(reply, &outcome.result),
            None => unanswered(reply, OUTCOME_FRAMES * 20),
        })
    }

    /// The driver's current configuration.
    #[must_use]
    pub fn config(&self) -> &DriverConfig {
        self.driver.params().config()
    }
}

impl Default for SimFrames {
    fn default() -> Self {
        Self::new()
    }
}

/// The shared state of a simulated head, leaked for `'static` as the
/// firmware's statics are.
#[must_use]
pub fn shared() -> (&'static CommandQueue, &'static ConsoleLink) {
    (
        Box::leak(Box::new(CommandQueue::new())),
        Box::leak(Box::new(ConsoleLink::new())),
    )
}

/// The parts of the Pico (`crates/rp/src/pico.rs`): trigger inputs on
/// GP2 to GP5, a DMX receiver, a radar.
#[must_use]
pub fn pico_parts() -> BoardParts {
    BoardParts {
        inputs: InputIds::new(&[2, 3, 4, 5]).expect("four distinct inputs"),
        dmx: true,
        radar: true,
    }
}

/// A console service for a simulated Pico ([`pico_parts`]) on the
/// built-in settings, with a RAM store.
#[must_use]
pub fn service(
    queue: &'static CommandQueue,
    link: &'static ConsoleLink,
) -> ConsoleService<'static, RamStorage> {
    ConsoleService::with_defaults(queue, link, RamStorage::new())
        .with_show(Box::leak(Box::new(ShowLink::new())))
        .with_parts(pico_parts())
}
