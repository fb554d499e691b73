//! The behaviour mixer alone (no driver): gesture shapes against their
//! documented formula, the structure of multi-cycle nods, smooth entries,
//! exits and blends, gaze glides, idle gain and duck.

use std::f64::consts::TAU;

use idle_head_core::Angle;
use idle_head_core::behaviour::{Applied, GesturePlan, LimitMode, LookApplied, Mixer};
use idle_head_core::command::{Action, GestureKind, GestureRequest, Hold, LookRequest, Percent};
use idle_head_core::gestures::Shape;
use idle_head_core::units::Millis;

use host_tests::behaviour::{default_params as params, frame, gesture};

fn plan_of(applied: Applied) -> GesturePlan {
    match applied {
        Applied::Gesture(plan) => plan,
        other => panic!("not a gesture: {other:?}"),
    }
}

/// Frames of one axis from the mixer over a still idle, `frames` long.
fn run(mixer: &mut Mixer, from: u64, frames: u64, axis: usize) -> Vec<f64> {
    (from..from + frames)
        .map(|k| f64::from(mixer.frame(frame(k), [Angle::ZERO; 3])[axis].millidegrees()))
        .collect()
}

fn smootherstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * x * (x * (6.0 * x - 15.0) + 10.0)
}

/// The shape of the gesture module's docs, in f64: `plan` `t` µs after
/// its start.
fn reference(plan: &GesturePlan, t: f64) -> f64 {
    let n = f64::from(plan.cycles);
    let a = f64::from(plan.amplitude.millidegrees());
    let phi = n * t / (f64::from(plan.duration.0) * 1000.0);
    let ramp = match plan.kind.shape() {
        Shape::Dip | Shape::Swing => 2.0,
        Shape::Lean => 3.0,
    };
    let envelope = if phi * ramp < 1.0 {
        smootherstep(phi * ramp)
    } else if (n - phi) * ramp < 1.0 {
        smootherstep((n - phi) * ramp)
    } else {
        1.0
    };
    let mut profile = a;
    if plan.cycles >= 2 {
        profile = a * (1.0 - (phi - 0.5) / (4.0 * n));
        profile *= 1.0 - 0.4 * smootherstep(phi - (n - 1.5));
    }
    let carrier = match plan.kind.shape() {
        Shape::Dip => (1.0 - (TAU * phi).cos()) / 2.0,
        Shape::Swing => (TAU * phi).sin(),
        Shape::Lean => 1.0,
    };
    envelope * profile * carrier
}

/// Frames (of 20 ms) that start before `plan` ends.
fn frames_of(plan: &GesturePlan) -> u32 {
    plan.duration.0.div_ceil(20)
}

#[test]
fn shapes_follow_the_documented_formula() {
    // Every gesture of the table at its defaults, and a few asked for.
    let defaults = GestureKind::ALL.map(|kind| gesture(kind, None, None, None));
    let cases = defaults.into_iter().chain([
        gesture(GestureKind::Nod, Some(6000), Some(900), None),
        gesture(GestureKind::Nod, Some(9000), Some(2000), Some(5)),
        gesture(GestureKind::Shake, None, None, None),
        gesture(GestureKind::Shake, Some(12_000), Some(1200), Some(2)),
        gesture(GestureKind::Tilt, Some(-9000), Some(1500), None),
    ]);
    for action in cases {
        let mut mixer = Mixer::new(params());
        let plan = plan_of(mixer.apply(&action).unwrap());
        let frames = frames_of(&plan);
        let played = run(
            &mut mixer,
            0,
            u64::from(frames) + 5,
            plan.kind.axis().index(),
        );
        for (k, &value) in played.iter().enumerate() {
            let t = k as f64 * 20_000.0;
            let expected = if (k as u32) < frames {
                reference(&plan, t)
            } else {
                0.0
            };
            assert!(
                (value - expected).abs() <= 2.0,
                "{plan:?} frame {k}: {value} m°, formula {expected:.1} m°"
            );
        }
    }
}

#[test]
fn defaults_resolve_as_documented() {
    let resolve = |action: &Action| plan_of(Mixer::new(params()).apply(action).unwrap());
    let nod = resolve(&gesture(GestureKind::Nod, None, None, None));
    // 2 cycles at 1.5 + 2·0.5 = 2.5 Hz; 6° × 1.05 (two cycles).
    assert_eq!(
        (nod.cycles, nod.duration, nod.amplitude.millidegrees()),
        (2, Millis(800), 6300)
    );
    let shake = resolve(&gesture(GestureKind::Shake, None, None, None));
    // 3 cycles at 1.85 Hz: 1622 ms; 8° × 1.1.
    assert_eq!(
        (shake.cycles, shake.duration, shake.amplitude.millidegrees()),
        (3, Millis(1622), 8800)
    );
    let tilt = resolve(&gesture(GestureKind::Tilt, None, None, None));
    assert_eq!(
        (tilt.cycles, tilt.duration, tilt.amplitude.millidegrees()),
        (1, Millis(1429), 10_000)
    );
    // Intensity: 100 % is faster and fuller, 0 % slower and softer.
    let brisk = GestureRequest {
        intensity: Some(Percent::FULL),
        ..GestureRequest::new(GestureKind::Nod)
    };
    let brisk = resolve(&Action::Gesture(brisk));
    assert_eq!(
        (brisk.duration, brisk.amplitude.millidegrees()),
        (Millis(571), 7875)
    );
    let soft = GestureRequest {
        intensity: Some(Percent::ZERO),
        ..GestureRequest::new(GestureKind::Nod)
    };
    let soft = resolve(&Action::Gesture(soft));
    assert_eq!(
        (soft.duration, soft.amplitude.millidegrees()),
        (Millis(1333), 4725)
    );
    // A duration alone: cycles from the tempo (0.9 s · 2.5 Hz = 2.25 → 2).
    let timed = resolve(&gesture(GestureKind::Nod, Some(6000), Some(900), None));
    assert_eq!((timed.cycles, timed.amplitude.millidegrees()), (2, 6000));
}

/// The peak of each cycle of one axis' run.
fn cycle_peaks(values: &[f64], cycles: usize, frames: usize) -> Vec<f64> {
    (0..cycles)
        .map(|k| {
            values[k * frames / cycles..(k + 1) * frames / cycles]
                .iter()
                .fold(0.0_f64, |m, v| m.max(v.abs()))
        })
        .collect()
}

#[test]
fn multi_cycle_nods_decline_and_end_smaller() {
    for cycles in 2..=6_u8 {
        let mut mixer = Mixer::new(params());
        let request = gesture(GestureKind::Nod, Some(8000), None, Some(cycles));
        let plan = plan_of(mixer.apply(&request).unwrap());
        let frames = frames_of(&plan) as usize;
        let values = run(&mut mixer, 0, frames as u64, 0);
        let peaks = cycle_peaks(&values, usize::from(cycles), frames);
        println!("{cycles} cycles: peaks {peaks:?}");
        // The first cycle peaks at the amplitude asked for.
        assert!((peaks[0] - 8000.0).abs() <= 2.0, "{peaks:?}");
        // Declination: each cycle lower than the one before.
        assert!(peaks.windows(2).all(|w| w[1] < w[0]), "{peaks:?}");
        // Final lowering: the last cycle well below the trend of the others
        // (the trend predicts 1 − (n − 1)/(4n) of the first).
        let n = f64::from(cycles);
        let trend = 8000.0 * (1.0 - (n - 1.0) / (4.0 * n));
        let last = peaks[peaks.len() - 1];
        assert!(last < 0.65 * trend && last > 0.55 * trend, "{peaks:?}");
    }
}

#[test]
fn default_amplitude_rises_with_the_number_of_cycles() {
    let first = |cycles| {
        let mut mixer = Mixer::new(params());
        plan_of(
            mixer
                .apply(&gesture(GestureKind::Nod, None, None, Some(cycles)))
                .unwrap(),
        )
        .amplitude
        .millidegrees()
    };
    let amplitudes: Vec<i32> = (1..=8).map(first).collect();
    assert_eq!(amplitudes, [6000, 6300, 6600, 6900, 7200, 7500, 7500, 7500]);
}

/// Largest |first| and |second| difference of `values`.
fn peaks(values: &[f64]) -> (f64, f64) {
    let d1 = values.windows(2).map(|w| (w[1] - w[0]).abs());
    let d2 = values.windows(3).map(|w| (w[2] - 2.0 * w[1] + w[0]).abs());
    (d1.fold(0.0, f64::max), d2.fold(0.0, f64::max))
}

#[test]
fn entries_and_exits_are_smooth() {
    for kind in GestureKind::ALL {
        let mut mixer = Mixer::new(params());
        let plan = plan_of(mixer.apply(&gesture(kind, None, None, None)).unwrap());
        let frames = frames_of(&plan) as usize;
        // A still frame before and after.
        let mut values = vec![0.0];
        values.extend(run(&mut mixer, 0, frames as u64 + 2, kind.axis().index()));
        let (v, a) = peaks(&values);
        // C2: at both ends the velocity and the acceleration start from zero:
        // the step into (out of) the first (last) moving frame and the change
        // of step there are small against the gesture's peaks (a bare carrier
        // would start with a full step or a full change of step).
        let n = values.len();
        for w in [&values[..3], &values[n - 3..]] {
            let (v_end, a_end) = peaks(w);
            assert!(
                v_end <= 0.05 * v && a_end <= 0.1 * a,
                "{kind:?}: {w:?}, peaks {v} {a}"
            );
        }
    }
}

#[test]
fn validated_peaks_bound_the_played_ones() {
    // The documented (Kv, Ka) bound every shape the mixer plays.
    let factors = |kind: GestureKind| match kind.shape() {
        Shape::Dip => (1.45, 1.85),
        Shape::Swing => (1.05, 1.65),
        Shape::Lean => (0.9, 1.32),
    };
    for kind in GestureKind::ALL {
        let cycle_range = 1..=kind.row().max_cycles.min(8);
        for cycles in cycle_range {
            for ms in [500, 900, 1600, 3000] {
                let mut mixer = Mixer::new(params());
                let request = gesture(kind, Some(4000), Some(ms), Some(cycles));
                let Ok(applied) = mixer.apply(&request) else {
                    continue;
                };
                let plan = plan_of(applied);
                let frames = frames_of(&plan);
                let values = run(&mut mixer, 0, u64::from(frames) + 1, kind.axis().index());
                let (v, a) = peaks(&values);
                let omega = TAU * f64::from(plan.cycles) / f64::from(frames); // per frame
                let carrier = if kind.shape() == Shape::Dip {
                    2000.0
                } else {
                    4000.0
                };
                let (kv, ka) = factors(kind);
                // Rounding to m°: up to 2 m° per step, 4 m° per change of step.
                assert!(
                    v <= kv * omega * carrier + 2.0,
                    "{kind:?} {cycles} {ms}: {v}"
                );
                assert!(
                    a <= ka * omega * omega * carrier + 4.0,
                    "{kind:?} {cycles} {ms}: {a}"
                );
            }
        }
    }
}

#[test]
fn an_interrupted_gesture_blends_into_the_new_one() {
    // A shake, interrupted by a nod at frame 30; then a second nod at 50
    // interrupting the first (same axis).
    let shake = gesture(GestureKind::Shake, Some(10_000), Some(1500), Some(3));
    let nod = gesture(GestureKind::Nod, Some(8000), Some(800), Some(2));
    let solo = |action: &Action, axis| {
        let mut m = Mixer::new(params());
        m.apply(action).unwrap();
        run(&mut m, 0, 200, axis)
    };
    let mut mixer = Mixer::new(params());
    mixer.apply(&shake).unwrap();
    let mut yaw = Vec::new();
    let mut pitch = Vec::new();
    for k in 0..200 {
        if k == 30 || k == 50 {
            mixer.apply(&nod).unwrap();
        }
        let o = mixer.frame(frame(k), [Angle::ZERO; 3]);
        pitch.push(f64::from(o[0].millidegrees()));
        yaw.push(f64::from(o[2].millidegrees()));
    }
    // The shake fades out within the blend (250 ms = 13 frames) after 30.
    assert!(yaw[44..].iter().all(|&v| v == 0.0), "{:?}", &yaw[28..50]);
    assert!(yaw[31..42].iter().any(|&v| v != 0.0));
    // Bound on a faded layer R·g: |Δ²| ≤ |R″|·|g| + 2|R′|·|Δg| + |Δ²g|, with
    // R a smootherstep over 12.5 frames (|R′| ≤ 1.875/12.5, |R″| ≤ 5.78/12.5²).
    let bound = |old: &[f64], new: &[f64]| {
        let g = old.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let (dg, d2g) = peaks(old);
        let (_, d2n) = peaks(new);
        5.78 / 156.25 * g + 2.0 * 1.875 / 12.5 * dg + d2g + d2n + 4.0
    };
    let shake_solo = solo(&shake, 2);
    let nod_solo = solo(&nod, 0);
    let (_, d2_yaw) = peaks(&yaw);
    let (_, d2_pitch) = peaks(&pitch);
    assert!(d2_yaw <= bound(&shake_solo, &[0.0; 3]), "yaw Δ² {d2_yaw}");
    assert!(
        d2_pitch <= bound(&nod_solo, &nod_solo),
        "pitch Δ² {d2_pitch}"
    );
    // And never a jump in angle: every step within the solo peaks' bound.
    let (v_yaw, _) = peaks(&yaw);
    let (v_shake, _) = peaks(&shake_solo);
    assert!(v_yaw <= v_shake + 0.3 * 10_000.0 / 1.0 / 12.5 * 1.875 + 2.0);
}

#[test]
fn three_layers_then_busy() {
    let mut mixer = Mixer::new(params());
    let nod = gesture(GestureKind::Nod, None, None, None);
    for _ in 0..3 {
        mixer.apply(&nod).unwrap();
    }
    let err = mixer.apply(&nod).unwrap_err();
    assert_eq!(err.code(), "busy");
    // The oldest two fade out over the blend (250 ms from the last frame
    // mixed): free at the first frame at or past it (frame 13, 260 ms), not
    // before; the answer is an upper bound, a frame past the blend.
    assert_eq!(
        err.to_string(),
        "gestures: every layer is busy; try again in 270 ms"
    );
    for k in 0..13 {
        mixer.frame(frame(k), [Angle::ZERO; 3]);
    }
    assert!(mixer.apply(&nod).is_err());
    mixer.frame(frame(13), [Angle::ZERO; 3]);
    assert!(mixer.apply(&nod).is_ok());
}

fn look(pitch: i32, yaw: i32, ms: Option<u32>, hold: Option<Hold>) -> Action {
    Action::Look(LookRequest {
        pitch: Angle::from_millidegrees(pitch),
        yaw: Angle::from_millidegrees(yaw),
        duration: ms.map(Millis),
        hold,
    })
}

fn look_applied(applied: Applied) -> LookApplied {
    match applied {
        Applied::Look(l) => l,
        other => panic!("not a look: {other:?}"),
    }
}

#[test]
fn a_look_is_a_minimum_jerk_move_then_a_hold_then_the_return() {
    let mut mixer = Mixer::new(params());
    let applied = look_applied(
        mixer
            .apply(&look(-5000, 20_000, None, Some(Hold::Return(Millis(1000)))))
            .unwrap(),
    );
    // 300 ms + 8 ms · 20°: 460 ms = 23 frames.
    assert_eq!(applied.duration, Millis(460));
    assert!(!applied.clamped);
    let frames = 23.0;
    let mj = |tau: f64| tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    let mut modes = Vec::new();
    for k in 0..200_u64 {
        // The modes in effect for frame k: asked for before it.
        modes.push(mixer.modes());
        let offsets = mixer.frame(frame(k), [Angle::ZERO; 3]);
        let [p, r, y] = offsets.map(|a| f64::from(a.millidegrees()));
        assert_eq!(r, 0.0);
        let tau = (k as f64 / frames).min(1.0);
        if k <= 23 {
            assert!((y - 20_000.0 * mj(tau)).abs() <= 2.0, "frame {k}: {y}");
            assert!((p + 5000.0 * mj(tau)).abs() <= 2.0, "frame {k}: {p}");
        } else if k < 23 + 50 {
            // Holding for 1 s.
            assert_eq!((p, y), (-5000.0, 20_000.0), "frame {k}");
        } else if k >= 23 + 50 + 23 {
            // Back at the centre (the return takes the rule's 460 ms too).
            assert_eq!((p, y), (0.0, 0.0), "frame {k}");
        }
    }
    // Gesture mode while moving and for 500 ms (25 frames) after each move.
    assert_eq!(modes[0][2], LimitMode::Gesture);
    assert_eq!(modes[0][1], LimitMode::Idle);
    assert_eq!(modes[23 + 24][2], LimitMode::Gesture);
    assert_eq!(modes[23 + 26][2], LimitMode::Idle);
    assert_eq!(modes[23 + 50][0], LimitMode::Gesture);
    assert_eq!(modes[199][0], LimitMode::Idle);
}

/// A glide in f64, as the glide module documents it: from a state
/// (position, velocity per frame, acceleration per frame²) to a target at
/// rest over `frames`.
struct RefGlide {
    start: f64,
    frames: f64,
    target: f64,
    r: [f64; 3],
}

impl RefGlide {
    fn new(start: f64, (p, v, a): (f64, f64, f64), target: f64, frames: f64) -> Self {
        let (d, v, a) = (target - p, v * frames, a * frames * frames);
        let r = [
            10.0 * d - 4.0 * v - a / 2.0,
            -15.0 * d + 7.0 * v + a,
            6.0 * d - 3.0 * v - a / 2.0,
        ];
        Self {
            start,
            frames,
            target,
            r,
        }
    }

    /// Position, velocity and acceleration at frame `k`.
    fn at(&self, k: f64) -> (f64, f64, f64) {
        let s = 1.0 - ((k - self.start) / self.frames).clamp(0.0, 1.0);
        let [r0, r1, r2] = self.r;
        let h = s * s * s * (r0 + r1 * s + r2 * s * s);
        let h1 = s * s * (3.0 * r0 + 4.0 * r1 * s + 5.0 * r2 * s * s);
        let h2 = s * (6.0 * r0 + 12.0 * r1 * s + 20.0 * r2 * s * s);
        (
            self.target - h,
            h1 / self.frames,
            -h2 / (self.frames * self.frames),
        )
    }
}

#[test]
fn a_new_look_while_moving_keeps_velocity_and_acceleration() {
    let mut mixer = Mixer::new(params());
    let frames = |applied: Applied| match applied {
        Applied::Look(l) => f64::from(l.duration.0) / 20.0,
        Applied::Center(ms) => f64::from(ms.0) / 20.0,
        other => panic!("{other:?}"),
    };
    let first = mixer
        .apply(&look(0, 25_000, Some(800), Some(Hold::Stay)))
        .unwrap();
    let mut reference = RefGlide::new(0.0, (0.0, 0.0, 0.0), 25_000.0, frames(first));
    let mut worst: f64 = 0.0;
    for k in 0..120 {
        let action = match k {
            // Half way, turn the other way; then back to the centre.
            15 => Some(look(0, -15_000, Some(900), Some(Hold::Stay))),
            40 => Some(Action::Center { duration: None }),
            _ => None,
        };
        if let Some(action) = action {
            let (target, applied) = match action {
                Action::Look(l) => (f64::from(l.yaw.millidegrees()), mixer.apply(&action)),
                _ => (0.0, mixer.apply(&action)),
            };
            // The new move starts at the last frame mixed, where the old one
            // is, as fast and as accelerated: continuous up to the
            // acceleration; the next frame is its first step.
            let start = k as f64 - 1.0;
            reference = RefGlide::new(start, reference.at(start), target, frames(applied.unwrap()));
        }
        let yaw = f64::from(mixer.frame(frame(k), [Angle::ZERO; 3])[2].millidegrees());
        let (expected, _, _) = reference.at(k as f64);
        worst = worst.max((yaw - expected).abs());
    }
    // The frame path agrees with the continuous blend within its rounding.
    assert!(worst <= 3.0, "{worst} m° off the reference");
    assert_eq!(reference.at(119.0).0, 0.0);
}

#[test]
fn a_long_move_stays_on_the_minimum_jerk_profile() {
    // From −23° to 32° yaw: 55°, the whole default range.
    let mut mixer = Mixer::new(params());
    mixer
        .apply(&look(0, -23_000, None, Some(Hold::Stay)))
        .unwrap();
    for k in 0..100 {
        mixer.frame(frame(k), [Angle::ZERO; 3]);
    }
    let applied = look_applied(
        mixer
            .apply(&look(0, 32_000, None, Some(Hold::Stay)))
            .unwrap(),
    );
    // 300 ms + 8 ms · 55° = 740 ms: 37 frames, from the last frame mixed
    // (99): frame 100 is its first step.
    assert_eq!(applied.duration, Millis(740));
    let mj = |tau: f64| tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    let worst = (0..=40_u32)
        .map(|t| {
            let yaw = mixer.frame(frame(100 + u64::from(t)), [Angle::ZERO; 3])[2];
            let expected = -23_000.0 + 55_000.0 * mj((f64::from(t + 1) / 37.0).min(1.0));
            (f64::from(yaw.millidegrees()) - expected).abs()
        })
        .fold(0.0, f64::max);
    assert!(worst <= 2.0, "{worst} m°");
}

#[test]
fn targets_outside_the_limits_are_clamped_and_said_so() {
    let mut mixer = Mixer::new(params());
    let applied = look_applied(mixer.apply(&look(40_000, -90_000, None, None)).unwrap());
    assert!(applied.clamped);
    // The default limits: pitch −12°..20°, yaw −23°..32°.
    assert_eq!(
        (applied.pitch, applied.yaw),
        (Angle::from_degrees(20), Angle::from_degrees(-23))
    );
    assert_eq!(applied.hold, Hold::Return(Millis(3000)));
    let last = (0..200)
        .map(|k| mixer.frame(frame(k), [Angle::ZERO; 3]))
        .nth(60)
        .unwrap();
    assert_eq!(last[0], Angle::from_degrees(20));
    assert_eq!(last[2], Angle::from_degrees(-23));
}

#[test]
fn a_short_given_look_duration_is_lengthened_to_the_limits() {
    let mut mixer = Mixer::new(params());
    // 27° in 100 ms would need 506 °/s: the 250 °/s gesture limit makes it
    // 1.875 · 27 / 250 = 202.5 ms, 203 whole ms.
    let applied = look_applied(mixer.apply(&look(0, 27_000, Some(100), None)).unwrap());
    assert_eq!(applied.duration, Millis(203));
    // Long enough: as given.
    let applied = look_applied(mixer.apply(&look(0, 26_000, Some(1000), None)).unwrap());
    assert_eq!(applied.duration, Millis(1000));
}

#[test]
fn idle_gain_and_duck() {
    let idle = [Angle::from_degrees(4); 3];
    let mut mixer = Mixer::new(params());
    assert_eq!(mixer.frame(frame(0), idle), idle);
    // Off over 1 s (50 frames), minimum jerk.
    assert_eq!(
        mixer.apply(&Action::Idle(false)).unwrap(),
        Applied::Idle(Percent::ZERO)
    );
    let pitch: Vec<i32> = (1..=60)
        .map(|k| mixer.frame(frame(k), idle)[0].millidegrees())
        .collect();
    // From frame 0, the last mixed: frame 1 (`pitch[0]`) is a step in.
    assert_eq!(pitch[0], 4000);
    assert_eq!(pitch[24], 2000);
    assert_eq!(pitch[49], 0);
    // Half amplitude while off: still off; on again: half.
    mixer.apply(&Action::IdleAmp(Percent::HALF)).unwrap();
    mixer.apply(&Action::Idle(true)).unwrap();
    assert_eq!(mixer.frame(frame(200), idle)[1], Angle::from_degrees(2));
    // A tilt ducks roll's idle by 60 % at full strength, smoothly.
    mixer.apply(&Action::IdleAmp(Percent::FULL)).unwrap();
    for k in 201..300 {
        mixer.frame(frame(k), idle);
    }
    let tilt = gesture(GestureKind::Tilt, Some(5000), Some(1500), None);
    mixer.apply(&tilt).unwrap();
    let roll: Vec<i32> = (300..380)
        .map(|k| mixer.frame(frame(k), idle)[1].millidegrees())
        .collect();
    // Mid-tilt (from frame 299, the last mixed): 5° + 4° · 0.4.
    assert_eq!(roll[36], 5000 + 1600);
    // Pitch and yaw are not ducked.
    assert_eq!(mixer.frame(frame(380), idle)[0], Angle::from_degrees(4));
}
