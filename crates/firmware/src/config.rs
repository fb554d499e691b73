//! The built-in configuration every board starts from, checked at compile
//! time: the driver's parameters, the loops' playback and joins, the
//! behaviour, and the loop set buffers' type.

pub use idle_head_core::behaviour::LOOP_DURATION;
use idle_head_core::behaviour::{BehaviourConfig, BehaviourParams};
use idle_head_core::driver::{DriverConfig, DriverParams};
use idle_head_core::idle::{IdleMode, IdleTiming, LoopSet};
use idle_head_core::motion::{DEFAULT_N, DEFAULT_WINDOW_CAP};
use idle_head_core::playback::Playback;

/// The built-in driver configuration's parameters ([`DriverConfig::DEFAULT`]:
/// 50 Hz frames and PWM, hobby servos on the anatomical limits, a 2 s fade),
/// checked at compile time.
pub const DEFAULT_PARAMS: DriverParams = match DriverConfig::DEFAULT.build() {
    Ok(p) => p,
    Err(e) => panic!("{}", e.message()),
};

/// The default loops played at the default frame period: a 30 s loop of 20
/// ms frames, 1500 frames a loop.
pub const DEFAULT_PLAYBACK: Playback =
    match Playback::new(LOOP_DURATION, DriverConfig::DEFAULT.frame_period, DEFAULT_N) {
        Ok(p) => p,
        Err(_) => panic!("invalid playback parameters"),
    };

/// [`DEFAULT_PLAYBACK`]'s loops joined over 100 frames: a join every 1400.
pub const DEFAULT_TIMING: IdleTiming = match IdleTiming::new(DEFAULT_PLAYBACK) {
    Ok(t) => t,
    Err(e) => panic!("{}", e.message()),
};

/// The built-in behaviour for the built-in driver configuration.
pub const DEFAULT_BEHAVIOUR: BehaviourParams = match BehaviourConfig::DEFAULT.build(&DEFAULT_PARAMS)
{
    Ok(params) => params,
    Err(e) => panic!("{}", e.message()),
};

/// The idle motion of the board images: never-repeating, or with the
/// `fixed-loop` feature the paper's fixed loop (set 0 replayed).
pub const IDLE_MODE: IdleMode = if cfg!(feature = "fixed-loop") {
    IdleMode::FixedLoop
} else {
    IdleMode::NeverRepeating
};

/// A loop set as the boards keep it: the default length, and a kernel
/// capacity of the default windows ([`DEFAULT_WINDOW_CAP`]).
pub type Set = LoopSet<DEFAULT_N, DEFAULT_WINDOW_CAP>;

/// A loop set buffer as the boards pass it between the tasks.
pub type SetRef = &'static mut Set;
