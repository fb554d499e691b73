//! A head on the host: the frame engine (`behaviour::Head`) over the real
//! loops of any seed, the frame driver on recorder channels (1 µs per
//! duty count), every frame recorded as the servos got it, at any servo
//! rate (and changing it between frames, as the frame task does).

use idle_head_core::behaviour::{
    Applied, BehaviourConfig, BehaviourParams, Head, LOOP_DURATION, LimitMode, RestState,
};
use idle_head_core::command::Action;
use idle_head_core::driver::{DriverConfig, DriverParams, FrameDriver};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadConfig, HeadTrajectories, Integral16};
use idle_head_core::motion::{Lcg, Trajectory};
use idle_head_core::playback::Player;
use idle_head_core::servo::ServoRate;
use idle_head_core::{Axis, Microseconds, Playback, Timestamp};

use crate::Recorder;

/// The loops the rig plays.
type Loops = HeadTrajectories<Integral16, DEFAULT_N>;

/// The idle of a rig: its loops, replayed.
pub type Idle = Player<'static, Trajectory<Integral16, DEFAULT_N>>;

/// One frame as the servos got it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Its time, µs from the first frame.
    pub at: u64,
    /// The mixer's offsets, m°.
    pub offsets: [i32; 3],
    /// The angles the driver commanded, m°.
    pub angles: [i32; 3],
    /// The pulses written, µs (0: none, relaxed).
    pub pulses: [u32; 3],
    /// The limit modes the driver had for this frame.
    pub modes: [LimitMode; 3],
    /// Where the head was in resting after the frame.
    pub rest: RestState,
}

/// A head on the built-in driver configuration (50 Hz unless told, 30 s
/// loops, 2 s fade); see the [module docs](self).
pub struct Rig {
    /// The frame engine.
    pub head: Head<Idle>,
    /// The frame driver.
    pub driver: FrameDriver<Recorder>,
    /// The next frame's index.
    pub frame: u64,
    /// The next frame's time, µs.
    pub at: u64,
    /// The frame period, µs.
    pub period: u32,
    /// A rate asked for: it takes effect at the next frame.
    pending: Option<Microseconds>,
    /// Every frame played.
    pub played: Vec<Frame>,
}

/// The loops of `seed` (pitch `seed`, roll and yaw the paper's LCG's next
/// two values; `None`: the Table 2 set), generated once per seed.
#[must_use]
pub fn loops(seed: Option<u32>) -> &'static Loops {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    static LOOPS: OnceLock<Mutex<HashMap<Option<u32>, &'static Loops>>> = OnceLock::new();
    let mut all = LOOPS.get_or_init(Mutex::default).lock().unwrap();
    all.entry(seed).or_insert_with(|| {
        let mut config: HeadConfig = DEFAULT_HEAD;
        if let Some(seed) = seed {
            let mut lcg = Lcg::new(seed);
            config.pitch.seed = seed;
            config.roll.seed = lcg.next_value();
            config.yaw.seed = lcg.next_value();
        }
        let mut head = Box::new(HeadTrajectories::new());
        head.generate(&config).expect("the loops of a seed");
        Box::leak(head)
    })
}

/// The idle of the loops of `seed` (see [`loops`]) played at `driver`'s
/// frame period.
///
/// # Panics
/// If the playback of the built-in loop length is refused.
#[must_use]
pub fn idle(driver: &DriverParams, seed: Option<u32>) -> Idle {
    let playback = Playback::new(LOOP_DURATION, driver.config().frame_period, DEFAULT_N)
        .expect("the default playback");
    let trajectories = loops(seed);
    Player::new(playback, Axis::ALL.map(|axis| trajectories.axis(axis)))
}

/// Asserts that every step and change of step of `frames` (angles, m°, and
/// the limit modes each axis had, one entry a frame of 20 ms) is within
/// the speed and acceleration limits of `behaviour` for that mode (+1 m°
/// and +2 m° for rounding): the limiter's guarantee.
///
/// # Panics
/// At the first frame past them.
pub fn assert_steps_within_limits(
    behaviour: &BehaviourParams,
    frames: &[([i32; 3], [LimitMode; 3])],
) {
    for axis in Axis::ALL {
        let i = axis.index();
        for (k, w) in frames.windows(3).enumerate() {
            let limits = behaviour.limits(axis, w[2].1[i]);
            // deg/s · 20 ms, deg/s² · (20 ms)², in m°.
            let step = i64::from(limits.max_speed.0) * 20 + 1;
            let turn = i64::from(limits.max_accel.0) * 2 / 5 + 2;
            let [a, b, c] = [w[0].0, w[1].0, w[2].0].map(|angles| i64::from(angles[i]));
            assert!(
                (c - b).abs() <= step,
                "{axis:?} frame {}: step {}",
                k + 2,
                c - b
            );
            assert!(
                (c - 2 * b + a).abs() <= turn,
                "{axis:?} frame {}: Δ² {}",
                k + 2,
                c - 2 * b + a
            );
        }
    }
}

/// Asserts that `frames` (as a rig played them, at any rate and across
/// changes of it) keep the speed and acceleration limits of `behaviour`
/// in °/s and °/s², in the mode each axis had: each step within the speed
/// limit over the time since the last frame (+1 m° for rounding), and each
/// step within the acceleration limit of the last step carried over to the
/// new frame period (`Δₖ₋₁ · dtₖ / dtₖ₋₁`, the speed it was) (+3 m°).
///
/// # Panics
/// At the first frame past them.
pub fn assert_physical_limits(behaviour: &BehaviourParams, frames: &[Frame]) {
    for axis in Axis::ALL {
        let i = axis.index();
        for w in frames.windows(3) {
            let limits = behaviour.limits(axis, w[2].modes[i]);
            let (dt0, dt1) = ((w[1].at - w[0].at) as f64, (w[2].at - w[1].at) as f64);
            let [a, b, c] = [w[0], w[1], w[2]].map(|f| f64::from(f.angles[i]));
            // °/s · µs = µ°; /1000: m°.
            let step = f64::from(limits.max_speed.0) * dt1 / 1000.0 + 1.0;
            let turn = f64::from(limits.max_accel.0) * dt1 * dt1 / 1e9 + 3.0;
            let was = (b - a) * dt1 / dt0;
            assert!(
                (c - b).abs() <= step,
                "{axis:?} at {} µs: step {} m° over {dt1} µs",
                w[2].at,
                c - b
            );
            assert!(
                (c - b - was).abs() <= turn,
                "{axis:?} at {} µs: step {} m° after {b} − {a} over {dt0} µs: change {:.1} m°",
                w[2].at,
                c - b,
                c - b - was
            );
        }
    }
}

impl Rig {
    /// The built-in behaviour, the Table 2 loops.
    #[must_use]
    pub fn new() -> Self {
        Self::with(BehaviourConfig::DEFAULT, None)
    }

    /// The behaviour `config`, the loops of `seed`.
    #[must_use]
    pub fn with(config: BehaviourConfig, seed: Option<u32>) -> Self {
        Self::at_rate(config, seed, ServoRate::DEFAULT)
    }

    /// The behaviour `config`, the loops of `seed`, the servos at `rate`
    /// from the first frame.
    ///
    /// # Panics
    /// If the configuration is refused at that rate.
    #[must_use]
    pub fn at_rate(config: BehaviourConfig, seed: Option<u32>, rate: ServoRate) -> Self {
        let period = rate.period();
        let mut base = DriverConfig::DEFAULT;
        base.frame_period = period;
        base.pwm.period = period;
        let driver = base.build().expect("the default driver");
        let behaviour: BehaviourParams = config.build(&driver).expect("a valid behaviour");
        let recorder = || Recorder::new(period.0 as u16);
        Self {
            head: Head::new(idle(&driver, seed), behaviour),
            driver: FrameDriver::new([recorder(), recorder(), recorder()], driver),
            frame: 0,
            at: 0,
            period: period.0,
            pending: None,
            played: Vec::new(),
        }
    }

    /// The servos run at `rate` from the next frame on, as `servo rate`
    /// makes the frame task do: the outputs before that frame, the frames'
    /// spacing after it.
    pub fn set_rate(&mut self, rate: ServoRate) {
        self.pending = Some(rate.period());
    }

    /// Applies `action` before the next frame, as the frame task does.
    ///
    /// # Panics
    /// If the head refuses it.
    pub fn apply(&mut self, action: Action) -> Applied {
        self.head
            .apply(&mut self.driver, &action)
            .expect("the action plays")
    }

    /// Plays `frames` frames, as the frame task does (limits and relax
    /// between frames).
    ///
    /// # Panics
    /// If a rate asked for is refused.
    pub fn run(&mut self, frames: u64) {
        for _ in 0..frames {
            let pending = self.pending.take();
            if let Some(period) = pending {
                self.driver
                    .set_pwm_period(period)
                    .expect("the rate is taken");
            }
            self.head.sync(&mut self.driver);
            let modes = self.head.limit_modes();
            let at = self.at;
            let played = self.head.frame(&mut self.driver, Timestamp(at));
            if let Some(period) = pending {
                self.head
                    .set_frame_period(&mut self.driver, period)
                    .expect("the rate is taken");
                self.period = period.0;
            }
            let report = played.report;
            self.played.push(Frame {
                at,
                offsets: played.offsets.map(idle_head_core::Angle::millidegrees),
                angles: report.servos.map(|s| s.angle.millidegrees()),
                pulses: report.servos.map(|s| s.pulse.0),
                modes,
                rest: self.head.rest_state(),
            });
            self.frame += 1;
            self.at += u64::from(self.period);
        }
    }

    /// Plays frames for `ms` of time (at least one).
    pub fn run_ms(&mut self, ms: u64) {
        let until = self.at + ms * 1000;
        self.run(1);
        while self.at < until {
            self.run(1);
        }
    }

    /// Plays frames until `done` holds for the last one played, at most
    /// `frames`; returns how many it played.
    pub fn run_until(&mut self, frames: u64, done: impl Fn(&Frame) -> bool) -> u64 {
        for n in 1..=frames {
            self.run(1);
            if self.played.last().is_some_and(&done) {
                return n;
            }
        }
        frames
    }

    /// One axis' angles, m°, every frame played.
    #[must_use]
    pub fn axis(&self, axis: Axis) -> Vec<i32> {
        self.played.iter().map(|p| p.angles[axis.index()]).collect()
    }
}

impl Default for Rig {
    fn default() -> Self {
        Self::new()
    }
}
