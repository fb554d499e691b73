//! The fade envelope: the smoothstep fade-in after the start, fade-out on a
//! stop request, reversal mid-fade.

use host_tests::{direct_config, mdeg, params};
use idle_head_core::Millis;
use idle_head_core::driver::{DriverConfig, FrameDriver};

use super::{pitch_angles, recorders};

/// Smoothstep reference in floating point.
fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

#[test]
fn motion_fades_in_from_neutral_over_two_seconds() {
    let p = params(&DriverConfig::DEFAULT);
    assert_eq!(p.fade_frames(), 100); // 2 s / 20 ms
    let mut d = FrameDriver::new(recorders(), p);
    d.start();
    let a = pitch_angles(&mut d, [9000, 0, 0], 150);
    assert_eq!(a[0], 0, "the first frame after start is still neutral");
    for (k, &x) in a.iter().enumerate() {
        let want = 9000.0 * smoothstep(k as f64 / 100.0);
        assert!(
            (f64::from(x) - want).abs() <= 1.0,
            "frame {k}: {x} vs {want}"
        );
    }
    assert_eq!(a[50], 4500);
    assert_eq!(a[100..], [9000; 50]);
    // Never a step: at most 1.5 · 9° / 100 frames = 0.135° per frame.
    assert!(a.windows(2).all(|w| w[1] - w[0] <= 136));
    assert_eq!(d.release()[0].written[0], 1500);
}

#[test]
fn stop_fades_out_to_the_neutral_pose_and_holds_it() {
    let mut cfg = DriverConfig::DEFAULT;
    cfg.neutral_pose = mdeg([2000, 0, 0]);
    let mut d = FrameDriver::new(recorders(), params(&cfg));
    d.start();
    pitch_angles(&mut d, [9000, 0, 0], 150);
    assert!(!d.is_stopping());
    d.request_stop();
    assert!(d.is_stopping() && !d.is_stopped());
    let a = pitch_angles(&mut d, [9000, 0, 0], 150);
    assert_eq!(a[0], 11_000);
    assert!(
        a.windows(2).all(|w| w[1] <= w[0] && w[0] - w[1] <= 136),
        "{a:?}"
    );
    assert_eq!(a[100..], [2000; 50]);
    assert!(d.is_stopped());
    // 2° → 22.2 µs → 1522 µs.
    assert_eq!(d.channels_mut()[0].written.last(), Some(&1522));
    d.resume();
    assert!(!d.is_stopped());
    let a = pitch_angles(&mut d, [9000, 0, 0], 101);
    assert_eq!((a[0], a[100]), (2000, 11_000));
}

#[test]
fn stop_during_fade_in_reverses_smoothly() {
    let mut d = FrameDriver::new(recorders(), params(&DriverConfig::DEFAULT));
    d.start();
    let mut a = pitch_angles(&mut d, [9000, 0, 0], 30);
    d.request_stop();
    a.extend(pitch_angles(&mut d, [9000, 0, 0], 40));
    assert!(a.windows(2).all(|w| (w[1] - w[0]).abs() <= 136));
    assert_eq!(*a.last().unwrap(), 0);
    assert!(d.is_stopped());
}

/// The gain at level `l` of `n`: smoothstep of `x = ⌊l·2¹⁶/n⌋` in Q16, as
/// the driver specifies it (in 64 bits here).
fn gain(level: u64, frames: u64) -> u64 {
    let x = (level << 16) / frames;
    ((x * x * (3 * 65_536 - 2 * x)) >> 32).min(65_536)
}

#[test]
fn the_fade_is_the_specified_smoothstep_exactly() {
    // Fades of 1, 3, 7, 100 and 1000 frames, and one beyond 2¹⁶ frames.
    for frames in [1u64, 3, 7, 100, 1000, 70_001] {
        let mut cfg = direct_config();
        cfg.fade = Millis((frames * 20) as u32);
        let p = params(&cfg);
        assert_eq!(u64::from(p.fade_frames()), frames);
        let mut d = FrameDriver::new(recorders(), p);
        d.start();
        let check = |d: &mut FrameDriver<host_tests::Recorder>, level: u64| {
            check_level(d, frames, level);
        };
        let top = frames.min(1200);
        for level in 0..=top {
            check(&mut d, level);
        }
        if top == frames {
            check(&mut d, frames);
            d.request_stop();
            for level in (0..=frames).rev() {
                check(&mut d, level);
            }
            assert!(d.is_stopped());
        }
    }
}

/// Writes one frame of [`FADE_OFFSETS`] and checks each servo's angle is
/// the offset at fade `level` of `frames`, rounded to the nearest m°.
fn check_level(d: &mut FrameDriver<host_tests::Recorder>, frames: u64, level: u64) {
    let r = d.write_frame(mdeg(FADE_OFFSETS));
    for (i, &o) in FADE_OFFSETS.iter().enumerate() {
        let want = (i64::from(o) * gain(level, frames) as i64 + (1 << 15)) >> 16;
        assert_eq!(
            i64::from(r.servos[i].angle.millidegrees()),
            want,
            "{frames}: level {level}"
        );
    }
}

/// Offsets (m°) the exact fade tests play: large, negative and tiny.
const FADE_OFFSETS: [i32; 3] = [19_999, -13_999, -1];

#[test]
fn the_fade_stays_exact_when_it_reverses() {
    // Fades of 7, 100 and 70 001 frames, turned back twice on the way.
    for frames in [7u64, 100, 70_001] {
        let mut cfg = direct_config();
        cfg.fade = Millis((frames * 20) as u32);
        let mut d = FrameDriver::new(recorders(), params(&cfg));
        d.start();
        let check = |d: &mut FrameDriver<host_tests::Recorder>, level: u64| {
            check_level(d, frames, level);
        };
        let (up, down) = (frames * 3 / 5, frames / 5);
        for level in 0..=up {
            check(&mut d, level);
        }
        d.request_stop();
        for level in (down..=up + 1).rev() {
            check(&mut d, level);
        }
        d.resume();
        for level in down - 1..=frames {
            check(&mut d, level);
        }
    }
}

/// The gain `t` µs after the start frame for a fade of `fade` µs, as the
/// driver specifies it: the smoothstep of `x = ⌊(t − 20 ms)·2¹⁶/fade⌋`
/// (in 64 bits here; 0 before the fade-in begins, 1 once it ended).
fn gain_at(t: u64, fade: u64) -> u64 {
    let Some(level) = t.checked_sub(20_000) else {
        return 0;
    };
    if level >= fade {
        return 65_536;
    }
    let x = (level << 16) / fade;
    (x * x * (3 * 65_536 - 2 * x)) >> 32
}

#[test]
fn the_fade_is_the_same_in_time_at_any_rate_and_across_a_change() {
    use idle_head_core::Microseconds;
    // Frame periods (µs) one after the other, each for a while: the gain
    // at each frame is the fade's at the frame's time since the start.
    let plans: [&[(u32, u64)]; 4] = [
        &[(20_000, 3_000_000)],
        &[(3003, 3_000_000)],
        &[
            (5000, 700_000),
            (3003, 1_300_000),
            (20_000, 2_200_000),
            (16_667, 3_000_000),
        ],
        &[(3003, 10_000), (20_000, 3_000_000)],
    ];
    for plan in plans {
        let mut cfg = direct_config();
        cfg.frame_period = Microseconds(plan[0].0);
        cfg.pwm.period = Microseconds(plan[0].0);
        cfg.fade = Millis(2000);
        let fade = 2_000_000;
        let mut d = FrameDriver::new(
            [0; 3].map(|_| host_tests::Recorder::new(plan[0].0 as u16)),
            params(&cfg),
        );
        d.start();
        let mut t = u64::from(plan[0].0);
        for &(period, until) in plan {
            if Microseconds(period) != d.params().config().frame_period {
                d.set_pwm_period(Microseconds(period)).unwrap();
            }
            while t < until {
                let r = d.write_frame(mdeg(FADE_OFFSETS));
                if Microseconds(period) != d.params().config().frame_period {
                    d.set_frame_period(Microseconds(period)).unwrap();
                }
                for (i, &o) in FADE_OFFSETS.iter().enumerate() {
                    let want = (i64::from(o) * gain_at(t, fade) as i64 + (1 << 15)) >> 16;
                    assert_eq!(
                        i64::from(r.servos[i].angle.millidegrees()),
                        want,
                        "{plan:?} at {t} µs"
                    );
                }
                t += u64::from(d.params().config().frame_period.0);
            }
        }
    }
}
