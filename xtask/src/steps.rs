//! The speed and acceleration limits seen from the outside: the largest
//! step and change of step of an axis' angles, one a frame, against what
//! the behaviour's limits allow (as `host-tests/src/rig.rs` checks).

use idle_head_core::Axis;
use idle_head_core::behaviour::{BehaviourParams, LimitMode};

/// The largest step and change of step of one axis' angles, m°.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steps {
    /// Largest `|a[k+1] − a[k]|`, m° a frame.
    pub step: f64,
    /// Largest `|a[k+2] − 2·a[k+1] + a[k]|`, m° a frame².
    pub turn: f64,
}

impl Steps {
    /// Of `angles`, one a frame, in m° (0 where there are too few).
    pub fn of(angles: &[f64]) -> Self {
        let step = angles
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        let turn = angles
            .windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
            .fold(0.0, f64::max);
        Self { step, turn }
    }

    /// What `params` allow `axis` in `mode` in a frame (60 °/s and 600 °/s²
    /// at 20 ms: 1200 m° and 240 m°).
    pub fn allowed(params: &BehaviourParams, axis: Axis, mode: LimitMode) -> Self {
        let limits = params.limits(axis, mode);
        let frame_us = f64::from(params.frame_us());
        // °/s · µs / 1000 = m°; °/s² · µs² / 10⁹ = m°.
        Self {
            step: f64::from(limits.max_speed.0) * frame_us / 1e3,
            turn: f64::from(limits.max_accel.0) * frame_us * frame_us / 1e9,
        }
    }

    /// Whether neither is past `allowed`'s.
    pub fn within(self, allowed: Self) -> bool {
        self.step <= allowed.step && self.turn <= allowed.turn
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_idle_limits_are_1200_and_240_millidegrees_a_frame() {
        let (_, params) = crate::trace::built_in().unwrap();
        let of = |step, turn| Steps { step, turn };
        for axis in Axis::ALL {
            let allowed = Steps::allowed(&params, axis, LimitMode::Idle);
            assert_eq!(allowed, of(1200.0, 240.0));
        }
        let steps = Steps::of(&[0.0, 1000.0, 2200.0, 3400.0]);
        assert_eq!(steps, of(1200.0, 200.0));
        let yaw = Steps::allowed(&params, Axis::Yaw, LimitMode::Idle);
        assert!(steps.within(yaw));
        assert!(!Steps::of(&[0.0, 1201.0]).within(yaw));
        assert!(!Steps::of(&[0.0, 0.0, 241.0]).within(yaw));
    }
}
