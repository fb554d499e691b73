//! The show layer (`behaviour::show`) in the frame engine, with the real
//! loops and the frame driver: a lighting console's cues and Bottango's
//! curves over the idle, through the same link the firmware's DMX receiver
//! and console ports fill. Every frame within the speed and acceleration
//! limits of the mode its axis had.

use host_tests::rig::assert_steps_within_limits;
use host_tests::{Recorder, params};
use idle_head_core::Axis;
use idle_head_core::behaviour::{
    BehaviourConfig, BehaviourParams, Head, LimitMode, ShowEvents, ShowLink, Source,
};
use idle_head_core::bottango::{Curve, Op, line::CurveArgs};
use idle_head_core::command::{Action, GestureKind};
use idle_head_core::dmx::{Counters, Cue, DmxAddress, DmxSettings, Signal};
use idle_head_core::driver::{DriverConfig, DriverParams, FrameDriver};

type Idle = host_tests::rig::Idle;

fn behaviour(driver: &DriverParams) -> BehaviourParams {
    BehaviourConfig::DEFAULT.build(driver).unwrap()
}

/// One frame as it went out.
#[derive(Clone, Copy, Debug)]
struct Played {
    /// The mixer's and show layer's offsets, m°.
    offsets: [i32; 3],
    /// The angles the servos were sent, m°.
    angles: [i32; 3],
    modes: [LimitMode; 3],
    events: ShowEvents,
}

/// A head on the default configuration with a show link, and a twin
/// without one (what the head does on its own).
struct Rig {
    head: Head<Idle>,
    driver: FrameDriver<Recorder>,
    twin: host_tests::rig::Rig,
    link: &'static ShowLink,
    frame: u64,
    played: Vec<Played>,
}

impl Rig {
    fn new() -> Self {
        let driver = params(&DriverConfig::DEFAULT);
        let channels = || [0; 3].map(|_| Recorder::new(20_000));
        let link: &'static ShowLink = Box::leak(Box::new(ShowLink::new()));
        link.dmx.set(DmxSettings::DEFAULT);
        Self {
            head: Head::new(host_tests::rig::idle(&driver, None), behaviour(&driver)),
            driver: FrameDriver::new(channels(), driver),
            twin: host_tests::rig::Rig::new(),
            link,
            frame: 0,
            played: Vec::new(),
        }
    }

    /// Plays `frames` frames as the frame task does: the show's inputs
    /// between frames, each frame through the driver.
    fn run(&mut self, frames: u64) {
        for _ in 0..frames {
            let curves = self.link.curves.sample((self.frame * 20) as u32);
            let dmx = Some(self.link.dmx.latest());
            let at = host_tests::behaviour::frame(self.frame);
            let events = self.head.show(&mut self.driver, at, dmx, curves);
            if let Some(signal) = events.signal {
                self.link.dmx.set_signal(signal);
            }
            let modes = self.head.limit_modes();
            let frame = self.head.frame(&mut self.driver, at);
            self.played.push(Played {
                offsets: frame.offsets.map(|a| a.millidegrees()),
                angles: frame.report.servos.map(|s| s.angle.millidegrees()),
                modes,
                events,
            });
            self.twin.run(1);
            self.frame += 1;
        }
    }

    /// A good DMX frame with `cue`, as the receiver records it.
    fn dmx(&self, cue: Cue) {
        self.link.dmx.record(Some(cue), Counters::default());
    }

    /// Plays `frames` frames with `cue` arriving every frame (a console at
    /// 44 Hz sends about one a frame).
    fn dmx_for(&mut self, cue: Cue, frames: u64) {
        for _ in 0..frames {
            self.dmx(cue);
            self.run(1);
        }
    }

    /// The offsets of frame `k` of the head on its own (the twin's).
    fn own(&self, k: usize) -> [i32; 3] {
        self.twin.played[k].offsets
    }

    fn angle(&self, axis: Axis) -> i32 {
        self.played.last().unwrap().angles[axis.index()]
    }
}

/// Every frame within the speed and acceleration limits of its axis' mode
/// (the limiter's guarantee, so also the show layer's).
fn assert_safe(rig: &Rig) {
    let frames: Vec<_> = rig.played.iter().map(|p| (p.angles, p.modes)).collect();
    assert_steps_within_limits(rig.head.mixer().params(), &frames);
}

/// A cue: the yaw coarse slot at `yaw`, the mix at `mix`, idle at full.
fn cue(yaw: u8, mix: u8) -> Cue {
    Cue::from_slots(&[yaw, 0, 128, 0, 128, 0, mix, 0, 255, 0])
}

#[test]
fn a_full_mix_moves_yaw_across_its_limits_within_the_speed_limit() {
    let mut rig = Rig::new();
    rig.run(150); // past the 2 s fade-in
    rig.dmx_for(cue(200, 255), 100);
    let limits = DriverConfig::DEFAULT.servos[Axis::Yaw.index()].limits;
    let (lo, hi) = (limits.min.millidegrees(), limits.max.millidegrees());
    // Coarse 200, fine 0: 51 200 of 65 535.
    let want = lo + ((hi - lo) as i64 * 51_200 / 65_535) as i32;
    assert!(
        (rig.angle(Axis::Yaw) - want).abs() <= 1,
        "{} vs {want}",
        rig.angle(Axis::Yaw)
    );
    assert!(
        (f64::from(want - lo) / f64::from(hi - lo) - 200.0 / 255.0).abs() < 0.01,
        "about 200/255 of the way"
    );
    assert_eq!(rig.head.show_source(), Source::Dmx);
    assert_eq!(rig.played[150].modes[Axis::Yaw.index()], LimitMode::Gesture);
    // It got there as fast as the gesture limits allow: 250 °/s reached.
    let fastest = rig.played[150..]
        .windows(2)
        .map(|w| (w[1].angles[2] - w[0].angles[2]).abs())
        .max()
        .unwrap();
    assert!(fastest > 4000, "{fastest} m° a frame at most");
    assert_safe(&rig);
}

#[test]
fn dropped_frames_hand_back_to_the_idle_after_a_second_without_a_jump() {
    let mut rig = Rig::new();
    rig.run(150);
    rig.dmx_for(cue(30, 255), 60);
    assert_eq!(rig.link.dmx.signal(), Signal::Ok);
    let last = rig.played.len();
    // The console goes away: 49 more frames still follow it...
    rig.run(49);
    assert!(rig.played[last..].iter().all(|p| p.events.signal.is_none()));
    rig.run(1);
    assert_eq!(rig.played.last().unwrap().events.signal, Some(Signal::Lost));
    assert_eq!(rig.link.dmx.signal(), Signal::Lost);
    let lost = rig.played.len() - 1;
    rig.run(120);
    // ...then the pose hands back over 0.5 s (25 frames): from then on the
    // offsets are the head's own, exactly.
    for k in lost + 26..rig.played.len() {
        assert_eq!(rig.played[k].offsets, rig.own(k), "frame {k}");
    }
    assert_eq!(rig.head.show_source(), Source::None);
    // No jump: the offsets glide from the pose to the head's own, each
    // frame a small part of the way.
    for k in lost..lost + 26 {
        for i in 0..3 {
            let step = (rig.played[k + 1].offsets[i] - rig.played[k].offsets[i]).abs();
            assert!(step <= 3_000, "frame {k} axis {i}: {step} m°");
        }
    }
    assert_safe(&rig);
    // Back to the idle limits once the axes have settled.
    assert_eq!(rig.head.limit_modes(), [LimitMode::Idle; 3]);
}

#[test]
fn a_band_entry_fires_exactly_one_gesture() {
    let mut rig = Rig::new();
    rig.run(150);
    let with = |trigger: u8| {
        let mut c = cue(128, 0);
        c.trigger = trigger;
        c
    };
    // The band the slot is in when the head first hears the console does
    // not fire; entering the nod band does, once, however long it stays.
    rig.dmx_for(with(20), 10);
    rig.dmx_for(with(5), 10);
    rig.dmx_for(with(20), 100);
    rig.dmx_for(with(25), 10);
    let fired: Vec<Action> = rig
        .played
        .iter()
        .filter_map(|p| {
            p.events.fired.map(|(action, outcome)| {
                assert!(outcome.is_ok(), "{outcome:?}");
                action
            })
        })
        .collect();
    assert_eq!(fired.len(), 1, "{fired:?}");
    assert!(matches!(fired[0], Action::Gesture(g) if g.kind == GestureKind::Nod));
    // Into another band and back: each entry fires.
    rig.dmx_for(with(40), 60);
    rig.dmx_for(with(80), 60);
    rig.dmx_for(with(20), 60);
    let kinds: Vec<String> = rig
        .played
        .iter()
        .filter_map(|p| p.events.fired.map(|(a, _)| format!("{a:?}")))
        .collect();
    assert_eq!(kinds.len(), 4, "{kinds:?}");
    assert!(kinds[1].contains("Shake") && kinds[2].contains("Center") && kinds[3].contains("Nod"));
    assert_safe(&rig);
}

#[test]
fn the_intensity_slot_sets_the_idle_and_gives_it_back() {
    let mut rig = Rig::new();
    rig.run(150);
    let mut quiet = cue(128, 0);
    quiet.intensity = 51; // 20 %
    rig.dmx_for(quiet, 10);
    assert_eq!(rig.head.mixer().idle_amp().get(), 20);
    rig.run(60);
    assert_eq!(rig.head.mixer().idle_amp().get(), 100);
    // Switched off: given back at once.
    rig.dmx_for(quiet, 10);
    rig.link.dmx.set(DmxSettings {
        on: false,
        address: DmxAddress::FIRST,
    });
    rig.run(1);
    assert_eq!(rig.played.last().unwrap().events.signal, Some(Signal::Off));
    assert_eq!(rig.head.mixer().idle_amp().get(), 100);
}

fn ramp(start: u32, duration: u32, from: i32, to: i32) -> Curve {
    Curve::new(
        start,
        &CurveArgs {
            start: 0,
            duration,
            start_y: from,
            start_control: (i32::try_from(duration / 3).unwrap(), 0),
            end_y: to,
            end_control: (-i32::try_from(duration / 3).unwrap(), 0),
        },
    )
}

#[test]
fn a_bottango_curve_plays_and_the_idle_resumes_after_it() {
    let mut rig = Rig::new();
    rig.run(150);
    let curves = &rig.link.curves;
    curves.set_active(true);
    curves
        .apply(
            Axis::Yaw,
            Op::Register {
                min: -20_000,
                max: 20_000,
            },
        )
        .unwrap();
    curves
        .apply(
            Axis::Pitch,
            Op::Register {
                min: -10_000,
                max: 10_000,
            },
        )
        .unwrap();
    // Yaw from -20° to +20° over 2 s, from 3.2 s on (frame 160).
    curves
        .apply(Axis::Yaw, Op::Push(ramp(3200, 2000, 0, 8192)))
        .unwrap();
    rig.run(10);
    assert_eq!(rig.head.show_source(), Source::None);
    rig.run(100);
    assert_eq!(rig.head.show_source(), Source::Bottango);
    // On the curve: the offset is the curve's (neutral pose 0), roll and
    // pitch the head's own (pitch has no curve yet).
    for k in 161..260 {
        let t = (k as u32) * 20 - 3200;
        let want = -20_000 + (40_000 * i64::from(ramp(0, 2000, 0, 8192).at(t)) / 8192) as i32;
        assert!((rig.played[k].offsets[2] - want).abs() <= 6, "frame {k}");
        assert_eq!(rig.played[k].offsets[0], rig.own(k)[0]);
        assert_eq!(rig.played[k].offsets[1], rig.own(k)[1]);
    }
    // The curve ends at frame 260; half a second later the head is on its
    // own again, exactly.
    rig.run(120);
    for k in 287..rig.played.len() {
        assert_eq!(rig.played[k].offsets, rig.own(k), "frame {k}");
    }
    assert_eq!(rig.head.show_source(), Source::None);
    assert_safe(&rig);
}

#[test]
fn bottango_takes_precedence_over_dmx_and_hands_back_to_it() {
    let mut rig = Rig::new();
    rig.run(150);
    rig.dmx_for(cue(0, 255), 20);
    let curves = &rig.link.curves;
    curves.set_active(true);
    curves
        .apply(
            Axis::Yaw,
            Op::Register {
                min: 0,
                max: 10_000,
            },
        )
        .unwrap();
    curves
        .apply(
            Axis::Yaw,
            Op::Push(Curve::hold((rig.frame * 20) as u32, 8192)),
        )
        .unwrap();
    rig.dmx_for(cue(0, 255), 20);
    assert_eq!(rig.head.show_source(), Source::Bottango);
    assert_eq!(rig.played.last().unwrap().offsets[2], 10_000);
    // The hold ends after 1 s; the console still sends: DMX again.
    rig.dmx_for(cue(0, 255), 60);
    assert_eq!(rig.head.show_source(), Source::Dmx);
    assert_safe(&rig);
}
