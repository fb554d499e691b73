//! Calibration sweep (`cargo run --release --features calibrate`: the
//! calibration image, never the shipped one).
//!
//! Plays, through the same frame task and driver (fade-in, speed and
//! acceleration limits, angle and pulse clamps), a slow sweep instead of the
//! idle loop, and logs the pulse at each stop:
//!
//! | time        | what                                                      |
//! |-------------|-----------------------------------------------------------|
//! | 0 – 10 s    | every servo at neutral: fit the horns, check the centring |
//! | +0 – 4 s    | pitch: neutral → upper limit                              |
//! | +4 – 8 s    | pitch: hold at the upper limit (pulse logged)             |
//! | +8 – 16 s   | pitch: upper → lower limit                                |
//! | +16 – 20 s  | pitch: hold at the lower limit (pulse logged)             |
//! | +20 – 24 s  | pitch: lower limit → neutral                              |
//! | 34 – 58 s   | roll, the same                                            |
//! | 58 – 82 s   | yaw, the same                                             |
//!
//! then it starts over (82 s per round). The trigger is time: the sweep
//! starts 10 s after the first frame, which leaves time to watch the neutral
//! pose; press reset to see it again. The other axes stay at neutral while
//! one moves. Limits are the servo calibration's mechanical `limits`.

use idle_head_core::driver::Outcome;
use idle_head_core::{Angle, AngleRange, Axis, LoopSource, Microseconds, Millis, Playback};
use static_cell::StaticCell;

use crate::log;

use crate::frame::Frame;

/// Samples per second of the sweep timeline (one sample = 100 ms).
const RATE: usize = 10;
/// Neutral hold at the start: 10 s.
const HOLD_NEUTRAL: usize = 10 * RATE;
/// Ramp neutral ↔ limit: 4 s; limit to limit: twice that.
const RAMP: usize = 4 * RATE;
/// Hold at a limit: 4 s.
const HOLD: usize = 4 * RATE;
/// One axis: up, hold, across, hold, back = 4 + 4 + 8 + 4 + 4 = 24 s.
const AXIS_SPAN: usize = RAMP + HOLD + 2 * RAMP + HOLD + RAMP;
/// The whole round: 10 s + 3 · 24 s = 82 s = 820 samples.
const SAMPLES: usize = HOLD_NEUTRAL + 3 * AXIS_SPAN;

/// Playback of the sweep: 820 samples of 100 ms at the firmware's frame period.
pub const fn playback(frame_period: Microseconds) -> Playback {
    match Playback::new(
        Millis((SAMPLES * 1000 / RATE) as u32),
        frame_period,
        SAMPLES,
    ) {
        Ok(p) => p,
        Err(_) => panic!("invalid sweep playback"),
    }
}

/// Where in its own 24 s slot an axis is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Stop {
    Upper,
    Lower,
}

/// One axis' sweep as a loop of samples (computed, not stored).
#[derive(Clone, Copy, Debug)]
pub struct Sweep {
    axis: Axis,
    limits: AngleRange,
}

impl Sweep {
    /// The sweep of `axis` between `limits`.
    pub const fn new(axis: Axis, limits: AngleRange) -> Self {
        Self { axis, limits }
    }

    /// Sample `i` within this axis' slot, if it is in it.
    fn slot_sample(&self, i: usize) -> Option<usize> {
        let start = HOLD_NEUTRAL + self.axis.index() * AXIS_SPAN;
        i.checked_sub(start).filter(|&k| k < AXIS_SPAN)
    }
}

/// `from + (to − from) · k / n`, in millidegrees.
fn lerp(from: Angle, to: Angle, k: usize, n: usize) -> Angle {
    let (a, b) = (i64::from(from.millidegrees()), i64::from(to.millidegrees()));
    // k ≤ n ≤ 80, |b − a| < 2^32: no overflow; n > 0 by construction.
    let v = a + (b - a) * k as i64 / (n.max(1) as i64);
    Angle::from_millidegrees(v as i32)
}

impl LoopSource for Sweep {
    fn len(&self) -> usize {
        SAMPLES
    }

    fn angle(&self, index: usize) -> Angle {
        let Some(k) = self.slot_sample(index % SAMPLES) else {
            return Angle::ZERO;
        };
        let (lo, hi) = (self.limits.min, self.limits.max);
        let across = RAMP + HOLD;
        let hold_lo = across + 2 * RAMP;
        let back = hold_lo + HOLD;
        if k < RAMP {
            lerp(Angle::ZERO, hi, k, RAMP)
        } else if k < across {
            hi
        } else if k < hold_lo {
            lerp(hi, lo, k - across, 2 * RAMP)
        } else if k < back {
            lo
        } else {
            lerp(lo, Angle::ZERO, k - back, RAMP)
        }
    }
}

/// The sweeps of the three axes between the built-in limits, as the frame
/// task plays them instead of the idle. Call once.
pub fn player() -> idle_head_core::playback::Player<'static, Sweep> {
    static SWEEPS: StaticCell<[Sweep; 3]> = StaticCell::new();
    let limits =
        |axis: Axis| idle_head_core::driver::DriverConfig::DEFAULT.servos[axis.index()].limits;
    let sweeps: &'static [Sweep; 3] =
        SWEEPS.init(Axis::ALL.map(|axis| Sweep::new(axis, limits(axis))));
    idle_head_core::playback::Player::new(
        playback(idle_head_core::driver::DriverConfig::DEFAULT.frame_period),
        [&sweeps[0], &sweeps[1], &sweeps[2]],
    )
}

/// Logs the pulse at the end of each hold (the servo has settled there).
pub fn log_frame(frame: &Frame, playback: &Playback) {
    let (sample, _) = playback.position(frame.tick.frame);
    let (next, _) = playback.position(frame.tick.frame.saturating_add(1));
    if next == sample {
        return; // log once per sample boundary
    }
    if next == HOLD_NEUTRAL && sample + 1 == HOLD_NEUTRAL {
        let [p, r, y] = frame.report.servos;
        log::info!(
            "calibration: neutral pulses pitch {=u32} roll {=u32} yaw {=u32} us; sweep starts",
            p.pulse.0,
            r.pulse.0,
            y.pulse.0
        );
        return;
    }
    for axis in Axis::ALL {
        let start = HOLD_NEUTRAL + axis.index() * AXIS_SPAN;
        // Last samples of the two holds (see `Sweep::angle`).
        let ends = [
            (start + RAMP + HOLD - 1, Stop::Upper),
            (start + 3 * RAMP + 2 * HOLD - 1, Stop::Lower),
        ];
        for (end, stop) in ends {
            if sample == end {
                let servo = frame.report.servos[axis.index()];
                let name = if stop == Stop::Upper {
                    "upper"
                } else {
                    "lower"
                };
                if servo.outcome == Outcome::Written {
                    log::info!(
                        "calibration: {=str} at its {=str} limit {=i32} mdeg: pulse {=u32} us, duty {=u16}",
                        axis.name(),
                        name,
                        servo.angle.millidegrees(),
                        servo.pulse.0,
                        servo.duty.0
                    );
                } else {
                    log::warn!(
                        "calibration: {=str} at its {=str} limit: not written ({})",
                        axis.name(),
                        name,
                        servo.outcome
                    );
                }
            }
        }
    }
}
