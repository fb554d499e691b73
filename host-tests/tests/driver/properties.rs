//! Property tests: duties within the pulse limits and the motion within the
//! speed and acceleration limits for random configurations, loops and write
//! errors; and the 32-bit limiter step for step equal to its model in wide
//! arithmetic.

use host_tests::strategies::{calibration, calibration_in, config};
use host_tests::{Recorder, params};
use idle_head_core::driver::{
    DegreesPerSecond, DegreesPerSecondSquared, DriverConfig, FrameDriver, MotionLimits, Outcome,
};
use idle_head_core::servo::PwmTiming;
use idle_head_core::{Angle, Axis, Microseconds, Millis, Playback};
use proptest::prelude::*;

use super::reference::{Limits, Model};

/// A hobby servo, or one whose limits reach up to ±360° (at a few µs per
/// degree, to keep its pulses positive).
fn wide() -> impl Strategy<Value = idle_head_core::servo::ServoCalibration> {
    prop_oneof![calibration(), calibration_in(360_000, 1000..=3000)]
}

/// Largest change of step (m°) between frames the acceleration limit of
/// `axis` allows, plus 2 m° for the rounding of three positions.
fn accel_bound(cfg: &DriverConfig, axis: Axis) -> i64 {
    let f = i128::from(cfg.frame_period.get());
    let accel = i128::from(cfg.motion[axis.index()].max_accel.0) * f * f / 1_000_000;
    (accel / 1000) as i64 + 2
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(host_tests::cases(300)))]

    /// For random loops, calibrations, limits and write errors: every duty
    /// written lies within its servo's pulse range (except the single 0 that
    /// switches a failing servo off), every angle within the axis limits,
    /// and no frame-to-frame change exceeds the speed limit, nor any change
    /// of that change the acceleration limit, neither in the commanded angle
    /// nor between the pulses a servo actually received.
    #[test]
    fn duties_stay_in_range_and_speed_and_acceleration_are_limited(
        cfg in config(),
        loops in proptest::collection::vec([-60_000i32..60_000, -60_000i32..60_000, -60_000i32..60_000], 1..30),
        loop_ms in 20u32..5000,
        max_duty in prop_oneof![Just(20_000u16), Just(62_500), Just(u16::MAX), Just(999)],
        failures in [proptest::collection::vec(proptest::bool::weighted(0.2), 0..40),
                     proptest::collection::vec(proptest::bool::weighted(0.2), 0..40),
                     proptest::collection::vec(proptest::bool::weighted(0.05), 0..40)],
        stop_at in 0usize..400,
    ) {
        let p = params(&cfg);
        let n = loops.len();
        let axis_loop = |a: usize| loops.iter().map(|s| Angle::from_millidegrees(s[a])).collect::<Vec<_>>();
        let (lp, lr, ly) = (axis_loop(0), axis_loop(1), axis_loop(2));
        let play = Playback::new(Millis(loop_ms), cfg.frame_period, n).unwrap();
        let channels = failures.clone().map(|pattern| Recorder { max_duty, fail_pattern: pattern, ..Recorder::default() });
        let mut d = FrameDriver::new(channels, p);
        let first = d.start().servos.map(|s| s.angle);
        prop_assert_eq!(first, [Angle::ZERO; 3]);
        // Last angle each servo actually received and the step that brought
        // it there (the neutral pulse at 0°, at rest, is where the limiter
        // starts, whether or not that write worked). Every commanded angle
        // lies within one frame's speed and acceleration limits of them.
        let mut received = [0i64; 3];
        let mut received_step = [0i64; 3];
        for frame in 0..300u64 {
            if frame as usize == stop_at {
                d.request_stop();
            }
            let r = d.write_frame(play.offsets(frame, [lp.as_slice(), lr.as_slice(), ly.as_slice()]));
            for (i, axis) in Axis::ALL.into_iter().enumerate() {
                let angle = r.servos[i].angle;
                prop_assert!(cfg.servos[i].limits.contains(angle));
                let step = i64::from(angle.millidegrees()) - received[i];
                prop_assert!(step.abs() <= i64::from(p.max_step(axis).millidegrees()), "{axis:?}: {step}");
                let change = (step - received_step[i]).abs();
                prop_assert!(change <= accel_bound(&cfg, axis), "{axis:?} frame {frame}: {change}");
                if r.servos[i].outcome == Outcome::Written {
                    received[i] = i64::from(angle.millidegrees());
                    received_step[i] = step;
                }
            }
        }
        let disabled = d.stats().disabled;
        let timing = PwmTiming::SERVO_50HZ;
        for (i, ch) in d.release().iter().enumerate() {
            let lo = timing.duty(cfg.servos[i].min_pulse, max_duty).0;
            let hi = timing.duty(cfg.servos[i].max_pulse, max_duty).0;
            let (last, rest) = ch.written.split_last().unwrap();
            prop_assert!(rest.iter().all(|w| (lo..=hi).contains(w)), "{i}: {lo}..={hi} {:?}", ch.written);
            prop_assert!((lo..=hi).contains(last) || (disabled[i] && *last == 0));
        }
    }

    /// The driver's limiter equals its model, frame for frame, for angle
    /// limits up to ±360°, speed and acceleration limits from a crawl to
    /// instantaneous, frame periods from 1 to 20 ms, and targets that hold,
    /// jump (also far beyond the limits) and move.
    #[test]
    fn the_limiter_is_its_model(
        servos in [wide(), wide(), wide()],
        speeds in [1u32..=100_000, 1u32..=100_000, 1u32..=100_000],
        accels in [1u32..=100_000_000, 1u32..=100_000_000, 1u32..=100_000_000],
        frame_us in prop_oneof![Just(20_000u32), Just(10_000), Just(3_000), Just(1_000)],
        moves in proptest::collection::vec(([-450_000i32..450_000, -450_000i32..450_000, -450_000i32..450_000], 1usize..40, any::<bool>()), 1..20),
    ) {
        let mut cfg = DriverConfig::DEFAULT;
        cfg.frame_period = Microseconds(frame_us);
        cfg.fade = Millis(0);
        cfg.servos = servos;
        for i in 0..3 {
            cfg.motion[i] = MotionLimits {
                max_speed: DegreesPerSecond(speeds[i]),
                max_accel: DegreesPerSecondSquared(accels[i]),
            };
        }
        // An acceleration below the resolution is rejected, not modelled.
        prop_assume!(cfg.validate().is_ok());
        let limits = [0, 1, 2].map(|i| {
            let l = servos[i].limits;
            Limits::new(speeds[i], accels[i], frame_us, l.min.millidegrees(), l.max.millidegrees())
        });
        let mut d = FrameDriver::new([Recorder::new(20_000), Recorder::new(20_000), Recorder::new(20_000)], params(&cfg));
        d.start();
        let mut models = [Model::default(); 3];
        let mut from = [0i32; 3];
        let mut frame = 0;
        for (to, frames, ramp) in moves {
            for k in 1..=frames {
                // A ramp moves there in `frames` frames, a jump at once.
                let target = [0, 1, 2].map(|i| if ramp {
                    from[i] + ((i64::from(to[i]) - i64::from(from[i])) * k as i64 / frames as i64) as i32
                } else {
                    to[i]
                });
                let r = d.write_frame(target.map(Angle::from_millidegrees));
                for i in 0..3 {
                    let want = models[i].step(target[i], &limits[i]);
                    prop_assert_eq!(r.servos[i].angle.millidegrees(), want, "axis {} frame {}", i, frame);
                }
                frame += 1;
            }
            from = to;
        }
    }
}
