//! The integer O(N) engine against the direct-form f64 reference.

use crate::reference;

use idle_head_core::Axis;
use idle_head_core::motion::{
    AxisConfig, Closure, DEFAULT_HEAD, DEFAULT_N, Fnv1a, HannKernel, HeadConfig, HeadTrajectories,
    Integral16, Lcg, Mdeg16, Sample, Trajectory, generate_into,
};

fn engine<const N: usize>(
    seed: u32,
    w: u16,
    a1: i32,
    a2: i32,
    closure: Closure,
) -> (Vec<f64>, usize) {
    let cfg = AxisConfig::paper_row(seed, w, a1, a2).with_closure(closure);
    let k = HannKernel::new(w).unwrap();
    let mut t: Trajectory<Mdeg16, N> = Trajectory::new();
    let info = t.generate(&cfg, Axis::Yaw, &k).unwrap();
    (
        t.playback().map(|s| f64::from(s.0) / 1000.0).collect(),
        usize::from(info.split),
    )
}

#[test]
fn lcg_matches_the_recurrence() {
    let mut g = Lcg::new(127);
    let mut r = 127u32;
    for _ in 0..10_000 {
        r = reference::lcg(r);
        assert_eq!(g.next_value(), r);
    }
}

#[test]
fn seamless_matches_reference() {
    let mut worst: f64 = 0.0;
    for seed in 0..300u32 {
        let seed = seed.wrapping_mul(2_654_435_761);
        let (e, split) = engine::<900>(seed, 59, -9, 9, Closure::Seamless);
        let r = reference::seamless(seed, 900, 59, -9.0, 9.0);
        assert!(
            split.abs_diff(r.split) <= 1,
            "seed {seed}: split {split} vs {}",
            r.split
        );
        // Compare at the engine's split so that a near-tie does not shift the loop.
        let (lo, hi) = reference::minmax(&r.smoothed);
        let j: Vec<f64> = r.smoothed.clone();
        let want = reference::scaled_about(&j, split, lo, hi, -9.0, 9.0);
        for (a, b) in e.iter().zip(&want) {
            worst = worst.max((a - b).abs());
        }
    }
    println!(
        "seamless: worst |engine − reference| = {:.4} degrees",
        worst
    );
    assert!(worst <= 0.004, "worst error {worst}");
}

#[test]
fn paper_matches_reference() {
    let mut worst: f64 = 0.0;
    let mut same_split = 0;
    for seed in 0..300u32 {
        let seed = seed.wrapping_mul(2_654_435_761);
        let cfg = AxisConfig::paper_row(seed, 59, -9, 9).with_closure(Closure::Paper);
        let k = HannKernel::new(59).unwrap();
        let mut t: Trajectory<Mdeg16, 900> = Trajectory::new();
        let info = t.generate(&cfg, Axis::Yaw, &k).unwrap();
        let mut unrot: Vec<f64> = t.playback().map(|s| f64::from(s.0) / 1000.0).collect();
        unrot.rotate_right(usize::from(info.split));
        let r = reference::paper(seed, 900, 59, -9.0, 9.0);
        let mut want = r.final_deg.clone();
        want.rotate_right(r.split);
        for (a, b) in unrot.iter().zip(&want) {
            worst = worst.max((a - b).abs());
        }
        // The split is drawn among crossings of values rounded to the
        // millidegree; where both implementations see the same crossings they
        // must pick the same one.
        let sign = |v: f64| ((v * 1000.0).round() as i64).signum();
        let crossings = |v: &[f64]| {
            (0..899)
                .filter(|&i| sign(v[i + 1]) != sign(v[i]))
                .collect::<Vec<_>>()
        };
        let ours = crossings(&unrot);
        assert_eq!(ours.len(), usize::from(info.crossings));
        if ours == crossings(&want) {
            assert_eq!(usize::from(info.split), r.split, "seed {seed}");
            same_split += 1;
        }
    }
    println!(
        "paper: worst |engine − reference| = {worst:.4} degrees; same crossings for {same_split}/300 seeds"
    );
    assert!(worst <= 0.004, "worst error {worst}");
    assert!(same_split >= 250);
}

/// The three default loops, bit for bit: the checksum that the firmware
/// prints and `qemu/expected.log` records. A change of the engine's
/// arithmetic that moves any sample or scale shows here, on the host.
#[test]
fn default_loops_are_the_recorded_ones() {
    let mut head = Box::new(HeadTrajectories::<Integral16, DEFAULT_N>::new());
    head.generate(&DEFAULT_HEAD).unwrap();
    assert_eq!(head.checksum(), 0x11a5_b828);
}

/// Loops across lengths, windows, seeds and both closures, bit for bit as
/// the engine computed them when this test was written (one FNV-1a over
/// every sample, scale and outcome): the engine's code may be rewritten,
/// its loops may not move.
#[test]
fn loops_across_configurations_are_the_recorded_ones() {
    let mut h = Fnv1a::new();
    // Loops of any length, finalised and in playback order.
    for n in [16, 17, 100, 450, 899, 900, 1800, 4001, 8192] {
        for w in [3u16, 4, 15, 59, 60, 239, 511] {
            if usize::from(w) > n / 2 {
                continue;
            }
            let kernel = HannKernel::new(w).unwrap();
            for seed in [0u32, 1, 127, 259, 8821, 0xdead_beef, u32::MAX] {
                for closure in [Closure::Seamless, Closure::Paper] {
                    let cfg = AxisConfig::paper_row(seed, w, -12, 19).with_closure(closure);
                    let mut out = vec![Integral16::ZERO; n];
                    match generate_into(&mut out, &cfg, Axis::Roll, &kernel, &mut ()) {
                        Ok(info) => {
                            h.write(&info.split.to_le_bytes());
                            h.write(&info.crossings.to_le_bytes());
                            h.write(&info.up_steps.to_le_bytes());
                        }
                        Err(_) => h.write(b"error"),
                    }
                    for s in &out {
                        s.hash_into(&mut h);
                    }
                }
            }
        }
    }
    // The firmware's form: rings of raw integrals with their loop scales.
    for w in [3u16, 15, 59, 239, 450] {
        for seed in [0u32, 127, 0xdead_beef] {
            for closure in [Closure::Seamless, Closure::Paper] {
                let head = HeadConfig {
                    pitch: DEFAULT_HEAD.pitch.with_seed(seed).with_window(w),
                    roll: DEFAULT_HEAD.roll.with_seed(seed ^ 1).with_window(w),
                    yaw: DEFAULT_HEAD.yaw.with_seed(seed ^ 2).with_window(w),
                }
                .with_closure(closure);
                let mut loops = Box::new(HeadTrajectories::<Integral16, 900>::new());
                match loops.generate(&head) {
                    Ok(_) => h.write(&loops.checksum().to_le_bytes()),
                    Err(_) => h.write(b"error"),
                }
            }
        }
    }
    assert_eq!(h.finish(), 0x472d_c33b, "{:#010x}", h.finish());
}
