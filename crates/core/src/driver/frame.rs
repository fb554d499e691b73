//! The frame driver: per frame, three loop offsets in, three duties out.

use embedded_hal::pwm::{Error as _, SetDutyCycle};

use crate::axis::Axis;
use crate::servo::{Duty, ServoCalibration, ServoMap};
use crate::units::{Angle, Microseconds};

use super::config::slew_params;
use super::envelope::{Envelope, UNITY};
use super::limiter::{Slew, SlewParams};
use super::{DriverParams, DriverStats, FrameReport, Outcome, ServoReport};

mod rate;
mod retune;

/// Per-servo runtime state: everything a frame reads of one servo but its
/// calibration, in one place (on ARMv6-M a load reaches 124 bytes past a
/// pointer: small structs keep the frame path free of address arithmetic).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct ServoState {
    slew: Slew,
    limits: SlewParams,
    map: ServoMap,
    consecutive_failures: u16,
    disabled: bool,
}

/// Drives three servos frame by frame; see the [module docs](super).
///
/// ```
/// use embedded_hal::pwm::{ErrorType, SetDutyCycle};
/// use idle_head_core::driver::{DriverConfig, FrameDriver};
/// use idle_head_core::servo::Duty;
/// use idle_head_core::Angle;
///
/// /// A PWM channel that remembers its duty (20 000 ticks = 20 ms: 1 tick per µs).
/// struct Channel(u16);
/// impl ErrorType for Channel {
///     type Error = core::convert::Infallible;
/// }
/// impl SetDutyCycle for Channel {
///     fn max_duty_cycle(&self) -> u16 { 20_000 }
///     fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
///         self.0 = duty;
///         Ok(())
///     }
/// }
///
/// const PARAMS: idle_head_core::driver::DriverParams = match DriverConfig::DEFAULT.build() {
///     Ok(p) => p,
///     Err(e) => panic!("{}", e.message()),
/// };
/// let mut driver = FrameDriver::new([Channel(0), Channel(0), Channel(0)], PARAMS);
/// let report = driver.start();
/// assert_eq!(report.servos[0].duty, Duty(1500)); // neutral first
/// for _ in 0..200 {
///     driver.write_frame([Angle::from_degrees(9); 3]); // fade in (2 s = 100 frames)
/// }
/// assert_eq!(driver.release()[0].0, 1600); // 9° · 11.111 µs/° = 100 µs
/// ```
#[derive(Clone, Debug)]
pub struct FrameDriver<P> {
    channels: [P; 3],
    params: DriverParams,
    servos: [ServoState; 3],
    envelope: Envelope,
    /// The last report (the frame being written while a frame is written).
    last: FrameReport,
    /// Whether the start frame was written.
    started: bool,
    /// No pulses: every servo gets duty 0, its limiter held where it was.
    relaxed: bool,
    stats: DriverStats,
    /// The frame of the last fault log suggestion ([`NEVER`] before the first).
    last_log: u64,
    unlogged: u32,
}

/// `last_log` before the first fault log suggestion.
const NEVER: u64 = u64::MAX;

impl<P: SetDutyCycle> FrameDriver<P> {
    /// A driver for `channels` (`[pitch, roll, yaw]`). Reads each channel's
    /// maximum duty once (pitch, roll, yaw), so the channels' PWM period
    /// must be the configuration's `pwm.period` (an output that can change
    /// it is set with [`set_pwm_period`](Self::set_pwm_period)); writes
    /// nothing until [`start`](Self::start).
    pub fn new(channels: [P; 3], params: DriverParams) -> Self {
        let config = &params.config;
        let servo = |i: usize| {
            let cal = &config.servos[i];
            // Validated by `build`, the only way to a `DriverParams`.
            let limits = slew_params(
                Axis::ALL[i],
                config.motion[i],
                config.frame_period,
                cal.limits,
            );
            ServoState {
                slew: Slew::default(),
                limits: limits.unwrap_or(SlewParams::new(1, 1, 0, 0)),
                map: ServoMap::new(cal, config.pwm, channels[i].max_duty_cycle()),
                consecutive_failures: 0,
                disabled: false,
            }
        };
        let servos = [servo(0), servo(1), servo(2)];
        Self {
            channels,
            params,
            servos,
            envelope: Envelope::new(params.fade_us(), config.frame_period.0),
            last: FrameReport {
                frame: 0,
                servos: [IDLE; 3],
                written: 0,
                failed: 0,
                disabled: 0,
                should_log: false,
                unlogged_faults: 0,
            },
            started: false,
            relaxed: false,
            stats: DriverStats::default(),
            last_log: NEVER,
            unlogged: 0,
        }
    }

    /// Writes every servo's neutral pulse (0°): the first pulse a servo ever
    /// receives. The idle motion then fades in, from
    /// [`START_HOLD`](super::START_HOLD) on (at 50 Hz: from the next frame
    /// on). Once started, it writes nothing and returns the last frame's
    /// report.
    pub fn start(&mut self) -> FrameReport {
        if self.started {
            return self.last;
        }
        self.started = true;
        self.envelope.start();
        for i in 0..3 {
            let report = self.write_servo(i, Angle::ZERO);
            if let Some(slot) = self.last.servos.get_mut(i) {
                *slot = report;
            }
        }
        self.finish()
    }

    /// Writes one frame of `offsets` (`[pitch, roll, yaw]`, relative to the
    /// neutral pose); see the [module docs](super) for what happens to them.
    /// Before [`start`](Self::start), it starts instead (ignoring `offsets`).
    #[inline(never)]
    pub fn write_frame(&mut self, offsets: [Angle; 3]) -> FrameReport {
        if !self.started {
            return self.start();
        }
        if self.relaxed {
            return self.relaxed_frame();
        }
        let gain = self.envelope.next_gain();
        let [pitch, roll, yaw] = offsets;
        self.servo_frame(0, pitch, gain);
        self.servo_frame(1, roll, gain);
        self.servo_frame(2, yaw, gain);
        self.finish()
    }

    /// Servo `i`'s part of a frame: fade, limits, mapping, write; into the
    /// report being written.
    #[inline]
    fn servo_frame(&mut self, i: usize, offset: Angle, gain: u32) {
        let config = &self.params.config;
        let disable_after = self.params.disable_frames;
        let (Some(servo), Some(cal), Some(channel), Some(&pose), Some(slot)) = (
            self.servos.get_mut(i),
            config.servos.get(i),
            self.channels.get_mut(i),
            config.neutral_pose.get(i),
            self.last.servos.get_mut(i),
        ) else {
            return;
        };
        let target = pose.saturating_add(scale(offset, gain));
        servo.frame(cal, channel, target, disable_after, slot);
    }

    /// Stops the pulses from the next frame on (once started): each servo
    /// gets duty 0, its output held low, and goes limp; its limiter stays
    /// where it was, at rest. The fade stays where it was too.
    ///
    /// [`set_relaxed`](Self::set_relaxed)`(false)` brings the pulses back:
    /// the first one is the last one written before, and the head moves on
    /// from there within its limits (a servo that was moved by hand or
    /// slumped meanwhile is pulled back to it by its own controller).
    pub fn set_relaxed(&mut self, relaxed: bool) {
        self.relaxed = relaxed && self.started;
        if self.relaxed {
            for servo in &mut self.servos {
                servo.slew.halt();
            }
        }
    }

    /// Frames were missed (the frame task woke late: a flash erase held the
    /// interrupts off, say): the PWM repeated the last pulses meanwhile, so
    /// the servos stood still. Every limiter stops where it is, and the
    /// next frame accelerates from rest within the limits instead of going
    /// on at the speed it had before.
    pub fn held(&mut self) {
        for servo in &mut self.servos {
            servo.slew.halt();
        }
    }

    /// Whether the pulses are stopped ([`set_relaxed`](Self::set_relaxed)).
    #[must_use]
    pub const fn is_relaxed(&self) -> bool {
        self.relaxed
    }

    /// The angles the last frame commanded, `[pitch, roll, yaw]`: where the
    /// head is (or, relaxed, where it was left).
    #[must_use]
    pub fn angles(&self) -> [Angle; 3] {
        self.last.servos.map(|s| s.angle)
    }

    /// A frame without pulses: duty 0 on every servo still on.
    #[inline(never)]
    fn relaxed_frame(&mut self) -> FrameReport {
        self.envelope.hold();
        let disable_after = self.params.disable_frames;
        for ((servo, channel), slot) in self
            .servos
            .iter_mut()
            .zip(self.channels.iter_mut())
            .zip(self.last.servos.iter_mut())
        {
            let outcome = if servo.disabled {
                Outcome::Off
            } else {
                write_duty(servo, channel, Duty(0), disable_after)
            };
            *slot = ServoReport {
                angle: servo.slew.angle(),
                pulse: Microseconds(0),
                duty: Duty(0),
                outcome,
            };
        }
        self.finish()
    }

    /// Fades the motion out to the neutral pose (then holds it).
    pub fn request_stop(&mut self) {
        self.envelope.set_stopping(true);
    }

    /// Fades the motion in again after [`request_stop`](Self::request_stop).
    pub fn resume(&mut self) {
        self.envelope.set_stopping(false);
    }

    /// Whether a stop was requested and the fade-out has finished.
    #[must_use]
    pub fn is_stopped(&self) -> bool {
        self.envelope.is_stopped()
    }

    /// Whether a stop was requested.
    #[must_use]
    pub fn is_stopping(&self) -> bool {
        self.envelope.is_stopping()
    }

    /// Running totals.
    #[must_use]
    pub fn stats(&self) -> &DriverStats {
        &self.stats
    }

    /// The parameters in use.
    #[must_use]
    pub fn params(&self) -> &DriverParams {
        &self.params
    }

    /// The PWM channels, `[pitch, roll, yaw]`.
    pub fn channels_mut(&mut self) -> &mut [P; 3] {
        &mut self.channels
    }

    /// Gives the PWM channels back.
    pub fn release(self) -> [P; 3] {
        self.channels
    }

    /// Maps, writes and counts servo `i`'s angle.
    #[inline]
    fn write_servo(&mut self, i: usize, angle: Angle) -> ServoReport {
        let (Some(servo), Some(cal), Some(channel)) = (
            self.servos.get_mut(i),
            self.params.config.servos.get(i),
            self.channels.get_mut(i),
        ) else {
            return IDLE;
        };
        map_and_write(servo, cal, channel, angle, self.params.disable_frames)
    }

    /// Completes the report of the servos just written: totals, fault log
    /// throttling and the frame counter.
    #[inline]
    fn finish(&mut self) -> FrameReport {
        let report = &mut self.last;
        report.frame = self.stats.frames;
        report.should_log = false;
        let [a, b, c] = &report.servos;
        // Unrolled: the loop's counter costs as much as the comparisons.
        if a.outcome == Outcome::Written
            && b.outcome == Outcome::Written
            && c.outcome == Outcome::Written
        {
            report.written = 3;
            report.failed = 0;
            report.disabled = 0;
            report.unlogged_faults = self.unlogged;
        } else {
            self.count_faults();
        }
        self.stats.frames = self.stats.frames.saturating_add(1);
        self.last
    }

    /// Counts a frame's outcomes other than all written, and decides whether
    /// to log its write errors.
    #[inline(never)]
    fn count_faults(&mut self) {
        let report = &mut self.last;
        (report.written, report.failed, report.disabled) = (0, 0, 0);
        let totals = self
            .stats
            .faults
            .iter_mut()
            .zip(self.stats.disabled.iter_mut());
        for (s, (faults, disabled)) in report.servos.iter().zip(totals) {
            match s.outcome {
                Outcome::Written => report.written += 1,
                Outcome::Failed(_) => {
                    report.failed += 1;
                    *faults = faults.saturating_add(1);
                }
                Outcome::Disabled(_) => {
                    report.failed += 1;
                    report.disabled += 1;
                    *faults = faults.saturating_add(1);
                    *disabled = true;
                }
                Outcome::Off => {}
            }
        }
        self.unlogged = self.unlogged.saturating_add(u32::from(report.failed));
        let due = self.last_log == NEVER
            || report.frame.saturating_sub(self.last_log) >= u64::from(self.params.log_frames);
        if report.failed > 0 && (due || report.disabled > 0) {
            report.should_log = true;
            report.unlogged_faults = self.unlogged;
            self.unlogged = 0;
            self.last_log = report.frame;
        } else {
            report.unlogged_faults = self.unlogged;
        }
    }
}

/// A servo's report before anything happened.
const IDLE: ServoReport = ServoReport {
    angle: Angle::ZERO,
    pulse: Microseconds(0),
    duty: Duty(0),
    outcome: Outcome::Off,
};

impl ServoState {
    /// One frame of this servo towards `target`: limits, mapping, write;
    /// reported in `report`.
    #[inline(never)]
    fn frame<P: SetDutyCycle>(
        &mut self,
        cal: &ServoCalibration,
        channel: &mut P,
        target: Angle,
        disable_after: u16,
        report: &mut ServoReport,
    ) {
        let before = self.slew;
        let angle = self.slew.step(target, &self.limits);
        *report = map_and_write(self, cal, channel, angle, disable_after);
        if report.outcome != Outcome::Written {
            // The servo still holds the last pulse written: continue from
            // there, so that the next pulse it gets is within the limits.
            self.slew = before;
        }
    }
}

/// Maps, writes and counts one servo's angle.
#[inline]
fn map_and_write<P: SetDutyCycle>(
    servo: &mut ServoState,
    cal: &ServoCalibration,
    channel: &mut P,
    angle: Angle,
    disable_after: u16,
) -> ServoReport {
    let (pulse, duty) = servo.map.pulse_and_duty(cal, angle);
    let outcome = if servo.disabled {
        Outcome::Off
    } else {
        write_duty(servo, channel, duty, disable_after)
    };
    ServoReport {
        angle,
        pulse,
        duty,
        outcome,
    }
}

/// Writes `duty` to a servo that is still on, and counts the outcome: a
/// servo whose writes fail `disable_after` frames in a row is switched off
/// (the fault policy's time in frames).
#[inline]
fn write_duty<P: SetDutyCycle>(
    servo: &mut ServoState,
    channel: &mut P,
    duty: Duty,
    disable_after: u16,
) -> Outcome {
    match channel.set_duty_cycle(duty.0) {
        Ok(()) => {
            servo.consecutive_failures = 0;
            Outcome::Written
        }
        Err(e) => {
            let kind = e.kind();
            servo.consecutive_failures = servo.consecutive_failures.saturating_add(1);
            if servo.consecutive_failures >= disable_after {
                // Best effort: no pulses, the servo goes limp. Nothing
                // more can be done if this write fails too.
                let _ = channel.set_duty_cycle(0);
                servo.disabled = true;
                Outcome::Disabled(kind)
            } else {
                Outcome::Failed(kind)
            }
        }
    }
}

/// `offset · gain`, gain in Q16 (`0..=65 536`), rounded to the nearest m°
/// (halves up), in 32 bits: with `offset = h·2¹⁶ + l` (`0 ≤ l < 2¹⁶`),
/// `⌊(offset·g + 2¹⁵)/2¹⁶⌋ = h·g + ⌊(l·g + 2¹⁵)/2¹⁶⌋` exactly, where
/// `|h·g| < 2³¹` and `l·g + 2¹⁵ < 2³²` for `g < 2¹⁶`.
fn scale(offset: Angle, gain: u32) -> Angle {
    if gain >= UNITY {
        return offset;
    }
    let o = offset.millidegrees();
    let (high, low) = (o >> 16, (o & 0xFFFF) as u32);
    let rounded = ((low * gain + (1 << 15)) >> 16) as i32;
    Angle::from_millidegrees(high * gain as i32 + rounded)
}
