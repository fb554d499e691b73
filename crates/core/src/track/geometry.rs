//! Where a person is for the head: bearing and pitch, in integers.
//!
//! `idsp::atan2` (integer, no division, within about 0.01° of the exact
//! angle) and an integer square root: no floating point, which the
//! Cortex-M0+ has no unit for. The head's sign convention is `+yaw` to the
//! head's left and `+pitch` nose down (`docs/user/radar.md`).

use super::{Person, TrackSettings};

/// A turn in the `i32` of `idsp::atan2` (2³¹ is π) in m°, rounded.
fn to_mdeg(turn: i32) -> i32 {
    ((i64::from(turn) * 180_000 + (1 << 30)) >> 31) as i32
}

/// The angle of `(across, along)` from the `along` axis towards `across`,
/// m° in `−180 000..180 000`.
#[must_use]
pub fn angle(across: i32, along: i32) -> i32 {
    to_mdeg(idsp::atan2(across, along))
}

/// The person's horizontal distance from the sensor, mm (at most 46 341:
/// the coordinates are 16-bit).
#[must_use]
pub fn distance(person: &Person) -> u32 {
    let (x, y) = (
        person.x.0.clamp(-32_767, 32_767).unsigned_abs(),
        person.y.0.clamp(-32_767, 32_767).unsigned_abs(),
    );
    (x * x + y * y).isqrt()
}

/// The yaw that points the head at `person`, m°: the sensor's bearing
/// `mount` less the person's angle to the sensor's right.
#[must_use]
pub fn bearing(person: &Person, settings: &TrackSettings) -> i32 {
    let right = angle(person.x.0, person.y.0);
    let yaw = settings.mount_mdeg() - right;
    // Back into −180°..180°.
    if yaw > 180_000 {
        yaw - 360_000
    } else if yaw < -180_000 {
        yaw + 360_000
    } else {
        yaw
    }
}

/// The pitch that points the head at the person's eyes, m°: up (negative)
/// when the eyes are above the pivot (`track height`).
#[must_use]
pub fn pitch(person: &Person, settings: &TrackSettings) -> i32 {
    let d = distance(person).max(1) as i32;
    -angle(settings.height_mm(), d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::{Angle, Millimetres};

    fn at(x: i32, y: i32) -> Person {
        Person {
            x: Millimetres(x),
            y: Millimetres(y),
        }
    }

    #[test]
    fn angles_match_the_float_ones() {
        for (x, y) in [
            (0, 2000),
            (2000, 2000),
            (-782, 1713),
            (1, 6000),
            (-3000, 500),
        ] {
            let exact = f64::from(x).atan2(f64::from(y)).to_degrees() * 1000.0;
            let got = f64::from(angle(x, y));
            assert!((got - exact).abs() < 20.0, "{x},{y}: {got} vs {exact}");
        }
    }

    #[test]
    fn right_of_the_radar_is_negative_yaw_and_eyes_above_are_up() {
        let s = TrackSettings::DEFAULT;
        assert_eq!(bearing(&at(0, 2000), &s), 0);
        assert!((bearing(&at(2000, 2000), &s) + 45_000).abs() < 20);
        let mounted = TrackSettings {
            mount: Angle::from_degrees(170),
            ..s
        };
        // 170° − (−45°) wraps to −145°.
        assert!((bearing(&at(-2000, 2000), &mounted) + 145_000).abs() < 20);
        assert!((pitch(&at(0, 300), &s) + 45_000).abs() < 20);
        assert_eq!(distance(&at(3000, 4000)), 5000);
        assert_eq!(distance(&at(-40_000, 40_000)), 46_339);
    }
}
