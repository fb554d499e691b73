//! Loop playback: exact timing, interpolation, the seam.

use idle_head_core::playback::{LoopSource, Playback, PlaybackError, Player};
use idle_head_core::{Angle, Microseconds, Millis};
use proptest::prelude::*;

const FRAME: Microseconds = Microseconds(20_000);

fn sine(n: usize, amplitude: f64) -> Vec<Angle> {
    (0..n)
        .map(|i| {
            let phase = core::f64::consts::TAU * i as f64 / n as f64;
            Angle::from_millidegrees((amplitude * phase.sin()).round() as i32)
        })
        .collect()
}

#[test]
fn bad_parameters_are_rejected() {
    assert_eq!(
        Playback::new(Millis(0), FRAME, 900),
        Err(PlaybackError::ZeroLoopDuration)
    );
    assert_eq!(
        Playback::new(Millis(18_000), Microseconds(0), 900),
        Err(PlaybackError::ZeroFramePeriod)
    );
    assert_eq!(
        Playback::new(Millis(18_000), FRAME, 0),
        Err(PlaybackError::NoSamples)
    );
    if let Ok(too_many) = usize::try_from(u64::from(u32::MAX) + 1) {
        assert_eq!(
            Playback::new(Millis(18_000), FRAME, too_many),
            Err(PlaybackError::TooManySamples)
        );
    }
    let p = Playback::new(Millis(18_000), FRAME, 900).unwrap();
    assert_eq!(
        (p.loop_duration(), p.frame_period(), p.samples()),
        (Millis(18_000), FRAME, 900)
    );
}

#[test]
fn one_frame_per_sample_plays_the_samples() {
    // 900 samples over 18 s at 50 Hz: 900 frames, one per sample.
    let p = Playback::new(Millis(18_000), FRAME, 900).unwrap();
    for k in 0..2000u64 {
        assert_eq!(p.position(k), ((k % 900) as usize, 0));
    }
}

#[test]
fn loop_duration_is_independent_of_the_sample_count() {
    // 900 samples over 60 s: 3000 frames, 10/3 frames per sample.
    let p = Playback::new(Millis(60_000), FRAME, 900).unwrap();
    assert_eq!(p.position(0), (0, 0));
    assert_eq!(p.position(1), (0, 19_660)); // 0.3 · 65 536 = 19 660.8
    assert_eq!(p.position(10), (3, 0));
    assert_eq!(p.position(2999), (899, 45_875)); // 899.7
    assert_eq!(p.position(3000), (0, 0));
    // 900 samples over 9 s: every second sample is played.
    let p = Playback::new(Millis(9000), FRAME, 900).unwrap();
    assert_eq!(p.position(1), (2, 0));
    assert_eq!(p.position(450), (0, 0));
    // A loop that is not a whole number of frames: 1001 ms at 20 ms frames.
    // Frame 50 is at 1000 ms, frame 51 at 1020 ms = 19 ms into the second loop.
    let p = Playback::new(Millis(1001), FRAME, 1001).unwrap();
    assert_eq!(p.position(50), (1000, 0));
    assert_eq!(p.position(51), (19, 0));
}

#[test]
fn no_drift_after_years() {
    // 900 samples over 60 s; frame index after ten years at 50 Hz.
    let p = Playback::new(Millis(60_000), FRAME, 900).unwrap();
    let frames_per_loop = 3000u64;
    let years = 50 * 3600 * 24 * 365 * 10u64;
    let k = years - years % frames_per_loop;
    for j in 0..frames_per_loop {
        assert_eq!(p.position(k + j), p.position(j), "frame {j}");
    }
    // Far beyond any run time: no overflow, still exact.
    let big = u64::MAX - u64::MAX % frames_per_loop;
    assert_eq!(p.position(big), (0, 0));
    assert_eq!(p.position(big - 1), p.position(frames_per_loop - 1));
}

#[test]
fn interpolation_hits_the_samples_and_follows_a_smooth_loop() {
    // A 10° sine in 36 samples, played 10 frames per sample.
    let samples = sine(36, 10_000.0);
    let p = Playback::new(Millis(36 * 200), FRAME, 36).unwrap();
    let mut worst = 0.0f64;
    for k in 0..720u64 {
        let got = p.offsets(k, [samples.as_slice(); 3])[0];
        if k % 10 == 0 {
            assert_eq!(got, samples[(k / 10) as usize % 36]);
        }
        let want = 10_000.0 * (core::f64::consts::TAU * k as f64 / 360.0).sin();
        worst = worst.max((f64::from(got.millidegrees()) - want).abs());
    }
    // Catmull-Rom on a sine with 10° steps: error well under 0.05°.
    assert!(worst < 50.0, "{worst}");
}

#[test]
fn the_seam_is_smooth() {
    // Frame 360 is sample 0 again, right after sample 35: the sine crosses zero
    // upwards there. The steps across it match each other and the steps at the
    // downward crossing in the middle of the loop (frame 180): no kink at the seam.
    let samples = sine(36, 10_000.0);
    let p = Playback::new(Millis(36 * 200), FRAME, 36).unwrap();
    let at = |k: u64| i64::from(p.offsets(k, [samples.as_slice(); 3])[1].millidegrees());
    let second_diff = |k: u64| at(k + 1) - 2 * at(k) + at(k - 1);
    let step = |k: u64| at(k + 1) - at(k);
    assert_eq!(at(360), 0);
    assert!(
        (step(359) - step(360)).abs() <= 2,
        "{} {}",
        step(359),
        step(360)
    );
    assert!((step(360) + step(180)).abs() <= 2);
    assert!(second_diff(360).abs() <= 2);
}

#[test]
fn three_loops_are_read_at_the_same_position() {
    let a: [Angle; 4] = [0, 1000, 2000, 3000].map(Angle::from_millidegrees);
    let b: [Angle; 4] = [0, -1000, -2000, -3000].map(Angle::from_millidegrees);
    let c: [Angle; 4] = [0; 4].map(Angle::from_millidegrees);
    let p = Playback::new(Millis(80), FRAME, 4).unwrap();
    assert_eq!(
        p.offsets(2, [&a, &b, &c]),
        [2000, -2000, 0].map(Angle::from_millidegrees)
    );
}

#[test]
fn slices_and_arrays_are_loop_sources() {
    let a: [Angle; 3] = [1, 2, 3].map(Angle::from_millidegrees);
    assert_eq!(LoopSource::len(&a), 3);
    assert_eq!(a.angle(4), Angle::from_millidegrees(2));
    let empty: &[Angle] = &[];
    assert!(LoopSource::is_empty(empty));
    assert_eq!(empty.angle(7), Angle::ZERO);
    // A loop shorter than the playback's sample count is read modulo its length.
    let p = Playback::new(Millis(80), FRAME, 4).unwrap();
    assert_eq!(
        p.offsets(3, [&a[..], &a[..], empty])[0],
        Angle::from_millidegrees(1)
    );
}

proptest! {
    #[test]
    fn position_is_in_range_for_any_frame(
        frame: u64, loop_ms in 1u32.., frame_us in 1u32.., samples in 1usize..100_000,
    ) {
        let p = Playback::new(Millis(loop_ms), Microseconds(frame_us), samples).unwrap();
        let (i, frac) = p.position(frame);
        prop_assert!(i < samples);
        prop_assert!(frac < 65_536);
        // Reference: the same position in exact rational arithmetic.
        let t = u128::from(frame) * u128::from(frame_us) % (u128::from(loop_ms) * 1000);
        let pos = t * samples as u128 * 65_536 / (u128::from(loop_ms) * 1000);
        prop_assert_eq!(i as u128 * 65_536 + u128::from(frac), pos);
    }

    /// Any sample values (full i32 range) and any position: no panic, and the
    /// spline stays within its four control points' range widened by a quarter
    /// of their span (Catmull-Rom overshoots by at most 1/8 of it).
    #[test]
    fn interpolation_never_panics_and_overshoots_little(
        values in proptest::collection::vec(any::<i32>(), 1..40),
        frame: u64, loop_ms in 1u32..100_000,
    ) {
        let samples: Vec<Angle> = values.iter().copied().map(Angle::from_millidegrees).collect();
        let p = Playback::new(Millis(loop_ms), FRAME, samples.len()).unwrap();
        let got = i64::from(p.offsets(frame, [samples.as_slice(); 3])[2].millidegrees());
        let (i, _) = p.position(frame);
        let n = samples.len();
        let pts: Vec<i64> = [n - 1, 0, 1, 2]
            .iter()
            .map(|d| i64::from(values[(i + d) % n]))
            .collect();
        let (lo, hi) = (*pts.iter().min().unwrap(), *pts.iter().max().unwrap());
        let slack = (hi - lo) / 4 + 1;
        prop_assert!(got >= (lo - slack).max(i64::from(i32::MIN)) && got <= (hi + slack).min(i64::from(i32::MAX)));
    }
}

#[test]
fn the_player_plays_the_default_loop_as_playback_does() {
    // 900 samples over 30 s at 20 ms frames: 5 frames for 3 samples.
    let samples: [Vec<Angle>; 3] = [sine(900, 9000.0), sine(900, -5000.0), sine(900, 12_000.0)];
    let loops = [
        samples[0].as_slice(),
        samples[1].as_slice(),
        samples[2].as_slice(),
    ];
    let p = Playback::new(Millis(30_000), FRAME, 900).unwrap();
    let mut player = Player::new(p, loops);
    for k in 0..3100u64 {
        assert_eq!(player.offsets(k), p.offsets(k, loops), "frame {k}");
    }
    assert_eq!(player.playback(), &p);
}

#[test]
fn the_player_stays_exact_after_years_and_late_frames() {
    // 900 samples over 60 s; frame index after ten years at 50 Hz.
    let samples = sine(900, 10_000.0);
    let loops = [samples.as_slice(); 3];
    let p = Playback::new(Millis(60_000), FRAME, 900).unwrap();
    let mut player = Player::new(p, loops);
    let years = 50 * 3600 * 24 * 365 * 10u64;
    // Late frames skip ahead, by one frame or by many; then frame by frame.
    // (The frames' time is µs in 64 bits: the last frames whose time fits.)
    let last = u64::MAX / u64::from(FRAME.0);
    for start in [years, years + 2, years + 1000, last - 5000] {
        for k in start..start + 3000 {
            assert_eq!(player.offsets(k), p.offsets(k, loops), "frame {k}");
        }
    }
}

proptest! {
    /// Any playback (loop duration, frame period, sample count) and any
    /// sequence of frames (the next one, a few skipped, a jump back or far
    /// ahead, the same again): the player gives exactly `Playback::offsets`.
    #[test]
    fn the_player_is_playback_frame_by_frame(
        values in proptest::collection::vec(-40_000i32..40_000, 1..60),
        big in proptest::collection::vec(any::<i32>(), 1..8),
        loop_ms in 1u32..200_000, frame_us in 1u32..100_000,
        samples in prop_oneof![1usize..100, 100usize..2000, Just(1 << 19), Just(1 << 20)],
        start: u64,
        moves in proptest::collection::vec(prop_oneof![
            8 => Just(1u64), 2 => 0u64..5, 1 => Just(0u64), 1 => any::<u64>()
        ], 1..300),
    ) {
        let a: Vec<Angle> = values.iter().copied().map(Angle::from_millidegrees).collect();
        let b: Vec<Angle> = big.iter().copied().map(Angle::from_millidegrees).collect();
        let loops = [a.as_slice(), b.as_slice(), a.as_slice()];
        let p = Playback::new(Millis(loop_ms), Microseconds(frame_us), samples).unwrap();
        let mut player = Player::new(p, loops);
        // Any frame whose time (µs, 64 bits) fits.
        let frames = u64::MAX / u64::from(frame_us);
        let mut frame = start % frames;
        for step in moves {
            frame = frame.wrapping_add(step) % frames;
            prop_assert_eq!(player.offsets(frame), p.offsets(frame, loops), "frame {}", frame);
        }
    }
}
