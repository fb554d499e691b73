//! Idle sources: what one frame of idle motion is.

use crate::playback::{LoopSource, Player};
use crate::units::{Angle, Microseconds, Millis, Timestamp};

/// Loop duration of the fixed idle loops on the boards: 30 s, the longer
/// end of the 15 to 30 s waits the paper recorded. With the 900 samples of a
/// loop (`DEFAULT_N`) that is 30 samples per second; at 50 frames per second
/// there are 30 s / 20 ms = 1500 frames per loop.
pub const LOOP_DURATION: Millis = Millis(30_000);

/// A source of idle motion: the offsets of each frame, `[pitch, roll, yaw]`,
/// relative to the neutral pose, at the frame's time.
///
/// Called once per frame with increasing times (a late frame skips some);
/// a source may keep state between calls, but the offsets of a frame must
/// not depend on how it was reached, so that the host and the firmware
/// play the same motion.
pub trait IdleSource {
    /// The idle offsets of the frame at `at`.
    fn offsets(&mut self, at: Timestamp) -> [Angle; 3];

    /// Frames come `period` apart after the last one played (the frame
    /// rate changed): a source that steps from one frame to the next works
    /// out its step here, between frames, not on the frame path.
    fn set_frame_period(&mut self, period: Microseconds) {
        let _ = period;
    }
}

/// The fixed loops, one per axis, replayed frame by frame (the paper's
/// loop: the same 30 s again and again).
///
/// ```
/// use idle_head_core::behaviour::IdleSource;
/// use idle_head_core::playback::Player;
/// use idle_head_core::{Angle, Microseconds, Millis, Playback, Timestamp};
///
/// let ramp: [Angle; 4] = [0, 1000, 2000, 1000].map(Angle::from_millidegrees);
/// let playback = Playback::new(Millis(160), Microseconds(20_000), 4).unwrap();
/// let mut idle = Player::new(playback, [&ramp, &ramp, &ramp]);
/// let at = Timestamp::of_frame(3, playback.frame_period());
/// assert_eq!(IdleSource::offsets(&mut idle, at), playback.offsets(3, [&ramp, &ramp, &ramp]));
/// ```
impl<L: LoopSource + ?Sized> IdleSource for Player<'_, L> {
    #[inline]
    fn offsets(&mut self, at: Timestamp) -> [Angle; 3] {
        Player::offsets_at(self, at)
    }

    fn set_frame_period(&mut self, period: Microseconds) {
        Player::set_frame_period(self, period);
    }
}
