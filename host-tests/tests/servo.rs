//! Servo calibration: validation, angle → pulse, pulse → duty.

use idle_head_core::servo::{
    Direction, Duty, NanosPerDegree, PwmTiming, ServoCalibration, ServoError, defaults,
};
use idle_head_core::{Angle, AngleRange, Axis, Microseconds};
use proptest::prelude::*;

const YAW: ServoCalibration = ServoCalibration::hobby(Axis::Yaw);
// The built-in calibrations are checked at compile time.
const _: () = YAW.assert_valid();
const _: () = ServoCalibration::hobby(Axis::Pitch).assert_valid();
const _: () = ServoCalibration::hobby(Axis::Roll).assert_valid();

#[test]
fn defaults_are_the_documented_hobby_servo() {
    assert_eq!(defaults::NEUTRAL, Microseconds(1500));
    assert_eq!(defaults::PER_DEGREE, NanosPerDegree(11_111));
    assert_eq!(
        (defaults::MIN_PULSE, defaults::MAX_PULSE),
        (Microseconds(1000), Microseconds(2000))
    );
    assert_eq!(PwmTiming::SERVO_50HZ.period, Microseconds(20_000));
    for axis in Axis::ALL {
        let cal = ServoCalibration::hobby(axis);
        assert_eq!(cal.validate(), Ok(()), "{axis:?}");
        assert_eq!(cal.limits, axis.anatomical_limits());
    }
}

#[test]
fn angle_to_pulse() {
    let cal = YAW;
    let p = |mdeg| cal.pulse(Angle::from_millidegrees(mdeg)).get();
    assert_eq!(p(0), 1500);
    assert_eq!(p(9_000), 1600);
    assert_eq!(p(-9_000), 1400);
    assert_eq!(p(45_000), 2000); // 1500 + 45 · 11.111 = 1999.995 → 2000
    assert_eq!(p(32_000), 1856); // 1855.55 → 1856
    assert_eq!(p(-23_000), 1244); // 1244.45 → 1244
    assert_eq!(p(45), 1500); // 45 m° · 11 111 ns/° = 0.499995 µs → 0
    assert_eq!(p(46), 1501); // 0.511106 µs → 1
    assert_eq!(p(-46), 1499); // symmetric
}

#[test]
fn reversed_servo_mirrors_the_pulse() {
    let cal = YAW.with_direction(Direction::Reversed);
    assert_eq!(cal.pulse(Angle::from_degrees(9)), Microseconds(1400));
    assert_eq!(cal.pulse(Angle::from_degrees(-9)), Microseconds(1600));
    assert_eq!(cal.pulse(Angle::from_millidegrees(46)), Microseconds(1499));
}

#[test]
fn pulse_is_clamped_to_the_servo_range() {
    let cal = YAW;
    assert_eq!(cal.pulse(Angle::from_degrees(90)), Microseconds(2000));
    assert_eq!(cal.pulse(Angle::from_degrees(-90)), Microseconds(1000));
    assert_eq!(
        cal.pulse(Angle::from_millidegrees(i32::MAX)),
        Microseconds(2000)
    );
    assert_eq!(
        cal.pulse(Angle::from_millidegrees(i32::MIN)),
        Microseconds(1000)
    );
    assert_eq!(
        cal.clamp_angle(Angle::from_degrees(40)),
        Angle::from_degrees(32)
    );
    assert_eq!(
        cal.clamp_angle(Angle::from_degrees(-40)),
        Angle::from_degrees(-23)
    );
}

#[test]
fn pulse_to_duty() {
    let t = PwmTiming::SERVO_50HZ;
    // 1 tick per µs.
    assert_eq!(t.duty(Microseconds(1500), 20_000), Duty(1500));
    // RP2040 at 125 MHz, divider 40: 3.125 MHz, TOP + 1 = 62 500 ticks per 20 ms.
    assert_eq!(t.duty(Microseconds(1000), 62_500), Duty(3125));
    assert_eq!(t.duty(Microseconds(1500), 62_500), Duty(4688)); // 4687.5 → 4688
    assert_eq!(t.duty(Microseconds(2000), 62_500), Duty(6250));
    // 16-bit full scale: 1500 · 65 535 / 20 000 = 4915.125 → 4915.
    assert_eq!(t.duty(Microseconds(1500), u16::MAX), Duty(4915));
    // Saturates at the full period.
    assert_eq!(t.duty(Microseconds(u32::MAX), u16::MAX), Duty(u16::MAX));
    assert_eq!(
        PwmTiming {
            period: Microseconds(0)
        }
        .duty(Microseconds(1), 100),
        Duty(100)
    );
    assert_eq!(t.duty(Microseconds(1500), 0), Duty(0));
}

#[test]
fn validation_rejects_each_problem_with_the_rejected_value() {
    let ok = ServoCalibration::hobby(Axis::Pitch);

    let mut c = ok;
    c.min_pulse = Microseconds(2000);
    assert_eq!(
        c.validate(),
        Err(ServoError::PulseRangeEmpty {
            min: Microseconds(2000),
            max: Microseconds(2000)
        })
    );

    let mut c = ok;
    c.neutral = Microseconds(2100);
    assert_eq!(
        c.validate(),
        Err(ServoError::NeutralOutsidePulseRange {
            neutral: Microseconds(2100),
            min: Microseconds(1000),
            max: Microseconds(2000),
        })
    );

    let mut c = ok;
    c.per_degree = NanosPerDegree(0);
    assert_eq!(c.validate(), Err(ServoError::ZeroPerDegree));

    let mut c = ok;
    c.limits = AngleRange::degrees(5, -5);
    assert_eq!(
        c.validate(),
        Err(ServoError::LimitsInverted { limits: c.limits })
    );

    let mut c = ok;
    c.limits = AngleRange::degrees(5, 10);
    assert_eq!(
        c.validate(),
        Err(ServoError::NeutralOutsideLimits { limits: c.limits })
    );

    // A range the servo cannot reach: ±60° needs 1500 ± 667 µs.
    let mut c = ok;
    c.limits = AngleRange::degrees(-60, 60);
    assert_eq!(
        c.validate(),
        Err(ServoError::LimitUnreachable {
            angle: Angle::from_degrees(-60),
            needed_us: 833,
            min: Microseconds(1000),
            max: Microseconds(2000),
        })
    );

    // Same for a reversed servo: the upper limit needs the short pulse.
    let mut c = ok.with_direction(Direction::Reversed);
    c.min_pulse = Microseconds(1400);
    assert_eq!(
        c.validate(),
        Err(ServoError::LimitUnreachable {
            angle: Angle::from_degrees(20),
            needed_us: 1278,
            min: Microseconds(1400),
            max: Microseconds(2000),
        })
    );

    // The messages name the field.
    assert!(ServoError::ZeroPerDegree.message().contains("`per_degree`"));
    assert!(
        ServoError::PulseRangeEmpty {
            min: Microseconds(0),
            max: Microseconds(0)
        }
        .message()
        .contains("`min_pulse`")
    );
}

/// Each error says what is wrong in µs and degrees, with the rejected values.
#[test]
fn servo_errors_read_in_the_users_units() {
    let shown = |edit: &dyn Fn(&mut ServoCalibration)| {
        let mut c = ServoCalibration::hobby(Axis::Pitch);
        edit(&mut c);
        c.validate().unwrap_err().to_string()
    };
    assert_eq!(
        shown(&|c| c.min_pulse = Microseconds(2500)),
        "min_pulse 2500 µs must be below max_pulse 2000 µs"
    );
    assert_eq!(
        shown(&|c| c.neutral = Microseconds(2100)),
        "neutral 2100 µs lies outside the pulse range 1000..2000 µs"
    );
    assert_eq!(
        shown(&|c| c.per_degree = NanosPerDegree(0)),
        "per_degree must be above 0 ns/°"
    );
    assert_eq!(
        shown(&|c| c.limits = AngleRange::degrees(5, -5)),
        "limits +5°..-5°: the lower limit lies above the upper one"
    );
    assert_eq!(
        shown(&|c| {
            c.limits = AngleRange {
                min: Angle::from_millidegrees(2_500),
                max: Angle::from_millidegrees(12_125),
            }
        }),
        "limits +2.5°..+12.125° must contain 0°, the neutral angle the servo starts at"
    );
    assert_eq!(
        shown(&|c| c.max_pulse = Microseconds(1700)),
        "limit +20° needs 1722 µs, outside the pulse range 1000..1700 µs"
    );
    assert_eq!(
        shown(&|c| c.limits = AngleRange::degrees(-60, 10)),
        "limit -60° needs 833 µs, outside the pulse range 1000..2000 µs"
    );
}

#[test]
fn nanos_per_degree_from_span() {
    assert_eq!(
        NanosPerDegree::from_span(Microseconds(1000), 90),
        NanosPerDegree(11_111)
    );
    assert_eq!(
        NanosPerDegree::from_span(Microseconds(2000), 180),
        NanosPerDegree(11_111)
    );
    assert_eq!(
        NanosPerDegree::from_span(Microseconds(1000), 0),
        NanosPerDegree(0)
    );
    assert_eq!(
        NanosPerDegree::from_span(Microseconds(u32::MAX), 1),
        NanosPerDegree(u32::MAX)
    );
}

proptest! {
    /// Whatever the calibration (valid or not) and angle: no panic, the pulse
    /// stays in [min, max] when that range is valid, and it is monotonic in the
    /// angle for the servo's direction.
    #[test]
    fn pulse_stays_in_range_and_is_monotonic(
        neutral in 0u32..4000, per_degree in 0u32..100_000, reversed: bool,
        min in 0u32..3000, span in 0u32..3000,
        a in any::<i32>(), b in any::<i32>(),
    ) {
        let cal = ServoCalibration {
            neutral: Microseconds(neutral),
            per_degree: NanosPerDegree(per_degree),
            direction: if reversed { Direction::Reversed } else { Direction::Normal },
            min_pulse: Microseconds(min),
            max_pulse: Microseconds(min + span),
            limits: AngleRange::degrees(-20, 20),
        };
        let (lo, hi) = (a.min(b), a.max(b));
        let (p_lo, p_hi) = (cal.pulse(Angle::from_millidegrees(lo)), cal.pulse(Angle::from_millidegrees(hi)));
        prop_assert!(p_lo.get() >= min && p_lo.get() <= min + span);
        prop_assert!(p_hi.get() >= min && p_hi.get() <= min + span);
        if reversed { prop_assert!(p_lo >= p_hi) } else { prop_assert!(p_lo <= p_hi) }
        let _ = cal.validate();
    }

    /// Duty is monotonic in the pulse and never exceeds max_duty.
    #[test]
    fn duty_is_monotonic_and_bounded(period in 0u32..100_000, max_duty: u16, a: u32, b: u32) {
        let t = PwmTiming { period: Microseconds(period) };
        let (lo, hi) = (a.min(b), a.max(b));
        let (d_lo, d_hi) = (t.duty(Microseconds(lo), max_duty), t.duty(Microseconds(hi), max_duty));
        prop_assert!(d_lo <= d_hi);
        prop_assert!(d_hi.0 <= max_duty);
    }
}
