//! Servo calibration: angle → pulse width → PWM duty ticks.
//!
//! A hobby servo turns to an angle set by the width of a pulse repeated every
//! PWM period (typically 1000..2000 µs every 20 ms). [`ServoCalibration`]
//! holds, per servo, the pulse at the neutral angle, the pulse change per
//! degree, the direction of rotation, the pulse limits and the mechanical angle
//! limits of the axis it drives. All conversions are integer arithmetic: no
//! floating point on the frame path.
//!
//! ```
//! use idle_head_core::servo::{ServoCalibration, PwmTiming, Duty};
//! use idle_head_core::{Angle, Axis, Microseconds};
//!
//! let cal = ServoCalibration::hobby(Axis::Yaw);
//! assert_eq!(cal.validate(), Ok(()));
//! assert_eq!(cal.pulse(Angle::ZERO), Microseconds(1500));
//! assert_eq!(cal.pulse(Angle::from_degrees(9)), Microseconds(1600));
//! assert_eq!(cal.pulse(Angle::from_degrees(-90)), Microseconds(1000)); // clamped
//! // 1500 µs of a 20 000 µs period with 62 500 ticks per period:
//! assert_eq!(PwmTiming::SERVO_50HZ.duty(Microseconds(1500), 62_500), Duty(4688));
//! ```

mod calibration;
mod map;
mod rate;

pub(crate) use calibration::Degrees;
pub use calibration::{
    Direction, Duty, NanosPerDegree, PwmTiming, ServoCalibration, ServoError, bounds, defaults,
};
pub use map::ServoMap;
pub use rate::{ServoRate, SetPeriod};
