//! What the driver reports per frame and in total.

use embedded_hal::pwm::ErrorKind;

use crate::servo::Duty;
use crate::units::{Angle, Microseconds};

/// What happened to one servo in a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outcome {
    /// The duty was written.
    Written,
    /// The write failed; the servo is written again next frame.
    Failed(ErrorKind),
    /// The write failed once too often: the servo was switched off this frame.
    Disabled(ErrorKind),
    /// The servo was switched off earlier and is not written any more.
    Off,
}

/// One servo's part of a [`FrameReport`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoReport {
    /// Commanded angle after fade, limits and clamping.
    pub angle: Angle,
    /// Pulse for that angle (clamped to the servo's pulse limits).
    pub pulse: Microseconds,
    /// Duty ticks for that pulse (the value written, unless `outcome` says otherwise).
    pub duty: Duty,
    /// Whether it was written.
    pub outcome: Outcome,
}

/// What [`FrameDriver::start`](super::FrameDriver::start) or
/// [`FrameDriver::write_frame`](super::FrameDriver::write_frame) did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameReport {
    /// The driver's frame count (0 for the start frame).
    pub frame: u64,
    /// Per servo, `[pitch, roll, yaw]`.
    pub servos: [ServoReport; 3],
    /// Servos written successfully.
    pub written: u8,
    /// Servos whose write failed (including the ones disabled this frame).
    pub failed: u8,
    /// Servos switched off this frame.
    pub disabled: u8,
    /// Whether to log this frame's faults: set for a newly disabled servo and
    /// otherwise at most once per [`FaultPolicy::log_interval`](super::FaultPolicy::log_interval).
    pub should_log: bool,
    /// Write errors since the last frame with `should_log` (including this frame's).
    pub unlogged_faults: u32,
}

/// Running totals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverStats {
    /// Frames issued (start frame included).
    pub frames: u64,
    /// Write errors per servo.
    pub faults: [u32; 3],
    /// Whether each servo has been switched off.
    pub disabled: [bool; 3],
}
