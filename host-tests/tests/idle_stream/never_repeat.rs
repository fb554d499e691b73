//! The never-repeat measure over an hour, against the fixed loop.

use std::thread;

use idle_head_core::idle::IdleMode;
use idle_head_core::motion::DEFAULT_HEAD;

use super::play;

/// The never-repeat measure of `frames` sampled every `stride` frames,
/// with windows of `window` samples: per lag from `window` to the last
/// that leaves a window, the smallest RMS difference of two windows that
/// far apart, each axis normalised by its standard deviation. Returns the
/// pose's and each axis' minimum, each with its lag in samples.
fn never_repeat(samples: &[[i32; 3]], window: usize) -> ((f64, usize), [(f64, usize); 3]) {
    let n = samples.len();
    let sigma2: [f64; 3] = std::array::from_fn(|a| {
        let mean = samples.iter().map(|s| f64::from(s[a])).sum::<f64>() / n as f64;
        samples
            .iter()
            .map(|s| (f64::from(s[a]) - mean).powi(2))
            .sum::<f64>()
            / n as f64
    });
    let inv: [f64; 3] = sigma2.map(|s| 1.0 / (s * window as f64));
    let lags: Vec<usize> = (window..=n - window).collect();
    // Each lag's windows slide over the squared differences, taken again at
    // the window's tail rather than stored: exact sums in integers. A
    // thread stops once its minima are all exactly 0 (as the fixed loop's
    // are at its period): no later lag can be smaller.
    let run = |lags: &[usize]| {
        let mut pose = (f64::MAX, 0);
        let mut axes = [(f64::MAX, 0); 3];
        for &lag in lags {
            let m = n - lag;
            let (x, y) = (&samples[..m], &samples[lag..]);
            let square = |t: usize, a: usize| i64::from(x[t][a] - y[t][a]).pow(2);
            let mut sum = [0i64; 3];
            for t in 0..m {
                for (a, s) in sum.iter_mut().enumerate() {
                    *s += square(t, a);
                }
                if t + 1 < window {
                    continue;
                }
                let norm: [f64; 3] = std::array::from_fn(|a| sum[a] as f64 * inv[a]);
                let p = (norm[0] + norm[1] + norm[2]) / 3.0;
                if p < pose.0 {
                    pose = (p, lag);
                }
                for (a, s) in sum.iter_mut().enumerate() {
                    if norm[a] < axes[a].0 {
                        axes[a] = (norm[a], lag);
                    }
                    *s -= square(t + 1 - window, a);
                }
            }
            if pose.0 == 0.0 && axes.iter().all(|a| a.0 == 0.0) {
                break;
            }
        }
        (pose, axes)
    };
    let (even, odd): (Vec<usize>, Vec<usize>) = lags.iter().partition(|&&l| l % 2 == 0);
    let (a, b) = thread::scope(|s| {
        let h = s.spawn(|| run(&even));
        let b = run(&odd);
        (h.join().unwrap(), b)
    });
    let pick = |x: (f64, usize), y: (f64, usize)| if x.0 <= y.0 { x } else { y };
    let pose = pick(a.0, b.0);
    let axes = std::array::from_fn(|i| pick(a.1[i], b.1[i]));
    let root = |(v, lag): (f64, usize)| (v.sqrt(), lag);
    (root(pose), axes.map(root))
}

#[test]
fn never_repeats_over_an_hour_and_the_fixed_loop_does() {
    // One hour of frames at 50 Hz, sampled at 10 Hz; 10 s windows.
    const FRAMES: usize = 180_000;
    const STRIDE: usize = 5;
    const WINDOW: usize = 100;
    let secs = |lag: usize| lag as f64 * STRIDE as f64 * 0.02;
    let mut results = vec![];
    for mode in [IdleMode::NeverRepeating, IdleMode::FixedLoop] {
        let frames = play(DEFAULT_HEAD, mode, FRAMES);
        let samples: Vec<[i32; 3]> = frames.iter().step_by(STRIDE).copied().collect();
        let (pose, axes) = never_repeat(&samples, WINDOW);
        println!(
            "{mode:?}: smallest windowed RMS difference over lags 10 s to 1 h: pose {:.3} at {:.1} s; pitch {:.3} at {:.1} s, roll {:.3} at {:.1} s, yaw {:.3} at {:.1} s",
            pose.0,
            secs(pose.1),
            axes[0].0,
            secs(axes[0].1),
            axes[1].0,
            secs(axes[1].1),
            axes[2].0,
            secs(axes[2].1)
        );
        results.push((pose, axes));
    }
    let (pose, axes) = results[0];
    assert!(pose.0 >= 0.15, "never-repeating pose {pose:?}");
    for a in axes {
        assert!(a.0 >= 0.02, "never-repeating axis {a:?}");
    }
    // The fixed loop replays exactly every 30 s (300 samples).
    let (pose, axes) = results[1];
    assert!(pose.0 < 1e-9 && pose.1 % 300 == 0, "fixed loop {pose:?}");
    assert!(axes.iter().all(|a| a.0 < 1e-9));
}
