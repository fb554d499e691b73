//! The frame path's servo map against the documented conversions
//! (`ServoCalibration::pulse`, `ServoCalibration::pulse_ps`,
//! `PwmTiming::duty_ps`), over every angle.

use host_tests::strategies::calibration;
use idle_head_core::servo::{
    Direction, Duty, NanosPerDegree, PwmTiming, ServoCalibration, ServoError, ServoMap,
};
use idle_head_core::{Angle, AngleRange, Axis, Microseconds};
use proptest::prelude::*;

/// Every angle from 2° below the lower limit to 2° above the upper one at
/// `timing`: the pulse in whole µs is the calibration's exactly, the duty
/// `PwmTiming::duty_ps` of the exact pulse or (the map's documented error:
/// its fraction may run over by less than a count) one count more. Returns
/// how many were one more.
fn check_every_angle_at(
    cal: &ServoCalibration,
    timing: PwmTiming,
    max_duty: u16,
) -> Result<usize, TestCaseError> {
    let map = ServoMap::new(cal, timing, max_duty);
    let lo = cal.limits.min.millidegrees() - 2000;
    let hi = cal.limits.max.millidegrees() + 2000;
    let mut off = 0;
    for a in lo..=hi {
        let angle = Angle::from_millidegrees(a);
        let pulse = cal.pulse(angle);
        prop_assert_eq!(map.pulse(cal, angle), pulse, "{} m°", a);
        let want = timing.duty_ps(cal.pulse_ps(angle), max_duty);
        let (got_pulse, got) = map.pulse_and_duty(cal, angle);
        prop_assert_eq!(got_pulse, pulse);
        prop_assert_eq!(map.duty(cal, angle), got);
        if got != want {
            prop_assert!(got.0 == want.0 + 1, "{} m°: {:?} vs {:?}", a, got, want,);
            off += 1;
        }
    }
    Ok(off)
}

/// [`check_every_angle_at`] at 50 Hz.
fn check_every_angle(cal: &ServoCalibration, max_duty: u16) -> Result<usize, TestCaseError> {
    check_every_angle_at(cal, PwmTiming::SERVO_50HZ, max_duty)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(host_tests::cases(64)))]

    /// The calibrations of the driver's property tests, on the channels they
    /// drive and on the Pico's (63 999: 64 000 counts per 20 ms).
    #[test]
    fn the_map_agrees_with_the_calibration_over_every_angle(
        cal in calibration(),
        max_duty in prop_oneof![Just(20_000u16), Just(62_500), Just(u16::MAX), Just(999), Just(65_465), Just(63_999)],
    ) {
        check_every_angle(&cal, max_duty)?;
    }

    /// The angle a duty maps back to gives that duty.
    #[test]
    fn a_duty_maps_back_to_an_angle_that_gives_it(
        cal in calibration(),
        max_duty in prop_oneof![Just(20_000u16), Just(62_500), Just(65_465), Just(63_999)],
        at in 0.0f64..=1.0,
    ) {
        let map = ServoMap::new(&cal, PwmTiming::SERVO_50HZ, max_duty);
        let (lo, hi) = (f64::from(cal.limits.min.millidegrees()), f64::from(cal.limits.max.millidegrees()));
        let angle = Angle::from_millidegrees((lo + at * (hi - lo)).round() as i32);
        let duty = map.duty(&cal, angle);
        let back = map.angle_of_duty(&cal, duty);
        prop_assert_eq!(map.duty(&cal, back), duty);
    }
}

/// The Pico's slices at 50, 200 and 333 Hz (`pwm_clock`): 64 000 counts
/// of 312.5 ns, 62 500 of 80 ns, 60 060 of 50 ns.
const PICO_RATES: [(u32, u16); 3] = [(20_000, 63_999), (5000, 62_499), (3003, 60_059)];

#[test]
fn the_default_servos_on_the_pico() {
    for (period, max_duty) in PICO_RATES {
        let timing = PwmTiming {
            period: Microseconds(period),
        };
        for axis in Axis::ALL {
            let cal = ServoCalibration::hobby(axis);
            for direction in [Direction::Normal, Direction::Reversed] {
                let cal = cal.with_direction(direction);
                let off = check_every_angle_at(&cal, timing, max_duty).unwrap();
                let angles = cal.limits.max.millidegrees() - cal.limits.min.millidegrees() + 4001;
                // One count more only near a whole count: a fraction of the angles.
                assert!(
                    off * 2 < angles as usize,
                    "{axis:?} at {period} µs: {off} of {angles}"
                );
            }
        }
    }
}

/// The first frame of a look at 200 Hz moves yaw by 16 m° (0.18 µs of
/// pulse, nothing in whole µs): the duty moves by the counts of 80 ns it
/// makes, at every rate whose count is finer than the step.
#[test]
fn a_step_below_a_microsecond_shows_in_the_duty() {
    let cal = ServoCalibration::hobby(Axis::Yaw);
    for (period, max_duty) in PICO_RATES {
        let timing = PwmTiming {
            period: Microseconds(period),
        };
        let map = ServoMap::new(&cal, timing, max_duty);
        let (from, to) = (Angle::ZERO, Angle::from_millidegrees(16));
        assert_eq!(map.pulse(&cal, from), map.pulse(&cal, to));
        // 177.776 ns in counts of period/(max_duty) … the exact count.
        let step_ns = 16.0 * 11.111;
        let count_ns = f64::from(period) * 1000.0 / f64::from(max_duty);
        let moved = map.duty(&cal, to).0 - map.duty(&cal, from).0;
        assert!(
            (f64::from(moved) - step_ns / count_ns).abs() < 1.0,
            "{period} µs: {moved} counts for {step_ns} ns of {count_ns} ns"
        );
        if step_ns > 2.0 * count_ns {
            assert!(moved >= 2, "{period} µs: {moved}");
        }
    }
}

#[test]
fn calibrations_beyond_the_32_bit_forms_take_the_documented_conversions() {
    // Pulses 100..19 000 µs: 17 500 µs from neutral, far beyond ±2100 µs.
    let wide = ServoCalibration {
        neutral: Microseconds(1500),
        per_degree: NanosPerDegree(1_000_000),
        direction: Direction::Normal,
        min_pulse: Microseconds(100),
        max_pulse: Microseconds(19_000),
        limits: AngleRange::degrees(-1, 17),
    };
    // No setting may write such pulses (the hard bounds refuse it); the
    // map on its own stays exact over them all the same.
    assert_eq!(
        wide.validate(),
        Err(ServoError::PulseOutsideBounds {
            max: false,
            pulse: Microseconds(100)
        })
    );
    check_every_angle(&wide, u16::MAX).unwrap();
    // Far outside the domain, the ends.
    let map = ServoMap::new(&wide, PwmTiming::SERVO_50HZ, u16::MAX);
    assert_eq!(
        map.pulse(&wide, Angle::from_millidegrees(i32::MAX)),
        Microseconds(19_000)
    );
    assert_eq!(
        map.duty(&wide, Angle::from_millidegrees(i32::MIN)),
        PwmTiming::SERVO_50HZ.duty(Microseconds(100), u16::MAX)
    );
    assert_eq!(
        map.duty(&wide, Angle::from_millidegrees(1)),
        PwmTiming::SERVO_50HZ.duty_ps(1_501_000_000, u16::MAX)
    );
    // A pulse outside the range gets the duty of the nearer end.
    let hobby = ServoCalibration::hobby(Axis::Yaw);
    let map = ServoMap::new(&hobby, PwmTiming::SERVO_50HZ, 20_000);
    assert_eq!(map.pulse_duty(&hobby, Microseconds(5)), Duty(1000));
    assert_eq!(map.pulse_duty(&hobby, Microseconds(3000)), Duty(2000));
    assert_eq!(map.max_duty(), 20_000);
}
