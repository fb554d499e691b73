//! The default limits against the real idle loops (motion engine, Table 2 set).

use host_tests::{Recorder, params};
use idle_head_core::driver::{DriverConfig, FrameDriver};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadTrajectories, Mdeg16, Trajectory};
use idle_head_core::{Angle, Axis, LoopSource, Microseconds, Millis, Playback};

/// Adapter until `Trajectory` implements `LoopSource` itself.
struct Loop<'a>(&'a Trajectory<Mdeg16, DEFAULT_N>);

impl LoopSource for Loop<'_> {
    fn len(&self) -> usize {
        DEFAULT_N
    }
    fn angle(&self, index: usize) -> Angle {
        self.0.angle(index)
    }
}

fn head() -> HeadTrajectories<Mdeg16, DEFAULT_N> {
    let mut h = HeadTrajectories::new();
    h.generate(&DEFAULT_HEAD).unwrap();
    h
}

/// Largest speed (°/s) and acceleration (°/s²) of the played offsets per axis.
fn extremes(play: &Playback, loops: [&Loop; 3], frames: u64) -> [(f64, f64); 3] {
    let dt = f64::from(play.frame_period().get()) * 1e-6;
    let mut out = [(0.0f64, 0.0f64); 3];
    let at = |k: u64| {
        play.offsets(k, loops)
            .map(|a| f64::from(a.millidegrees()) / 1000.0)
    };
    for k in 1..frames {
        let (a, b, c) = (at(k - 1), at(k), at(k + 1));
        for i in 0..3 {
            out[i].0 = out[i].0.max((c[i] - b[i]).abs() / dt);
            out[i].1 = out[i].1.max((c[i] - 2.0 * b[i] + a[i]).abs() / (dt * dt));
        }
    }
    out
}

#[test]
fn default_loops_are_far_inside_the_default_limits() {
    let h = head();
    let (p, r, y) = (
        Loop(h.axis(Axis::Pitch)),
        Loop(h.axis(Axis::Roll)),
        Loop(h.axis(Axis::Yaw)),
    );
    for loop_ms in [9_000, 18_000, 30_000] {
        let play = Playback::new(Millis(loop_ms), Microseconds(20_000), DEFAULT_N).unwrap();
        let frames = u64::from(loop_ms) / 20;
        let e = extremes(&play, [&p, &r, &y], frames);
        println!(
            "loop {loop_ms} ms: (°/s, °/s²) pitch {:.1?} roll {:.1?} yaw {:.1?}",
            e[0], e[1], e[2]
        );
        if loop_ms >= 18_000 {
            for (speed, accel) in e {
                assert!(speed < 30.0 && accel < 300.0, "{e:?}");
            }
        }
    }
}

#[test]
fn default_limits_leave_the_idle_loop_untouched() {
    let h = head();
    let (p, r, y) = (
        Loop(h.axis(Axis::Pitch)),
        Loop(h.axis(Axis::Roll)),
        Loop(h.axis(Axis::Yaw)),
    );
    let cfg = DriverConfig::DEFAULT;
    let play = Playback::new(Millis(18_000), cfg.frame_period, DEFAULT_N).unwrap();
    let mut d = FrameDriver::new(
        [
            Recorder::new(20_000),
            Recorder::new(20_000),
            Recorder::new(20_000),
        ],
        params(&cfg),
    );
    d.start();
    // Two loops plus: after the 2 s fade-in, the angles are exactly the loop.
    for k in 0..2000u64 {
        let offsets = play.offsets(k, [&p, &r, &y]);
        let report = d.write_frame(offsets);
        if k >= 100 {
            assert_eq!(report.servos.map(|s| s.angle), offsets, "frame {k}");
        }
    }
}
