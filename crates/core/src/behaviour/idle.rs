//! Idle sources: what one frame of idle motion is.

use crate::playback::{LoopSource, Player};
use crate::units::{Angle, Millis};

/// Loop duration of the fixed idle loops on the boards: 30 s, the longer
/// end of the 15 to 30 s waits the paper recorded. With the 900 samples of a
/// loop (`DEFAULT_N`) that is 30 samples per second; at 50 frames per second
/// there are 30 s / 20 ms = 1500 frames per loop.
pub const LOOP_DURATION: Millis = Millis(30_000);

/// A source of idle motion: the offsets of each frame, `[pitch, roll, yaw]`,
/// relative to the neutral pose.
///
/// Called once per frame with increasing frame indices (a late frame skips
/// some); a source may keep state between calls, but the offsets of a frame
/// must not depend on how it was reached, so that the host and the firmware
/// play the same motion.
pub trait IdleSource {
    /// The idle offsets of frame `frame`.
    fn offsets(&mut self, frame: u64) -> [Angle; 3];
}

/// The fixed loops, one per axis, replayed frame by frame (the paper's
/// loop: the same 30 s again and again).
///
/// ```
/// use idle_head_core::behaviour::IdleSource;
/// use idle_head_core::playback::Player;
/// use idle_head_core::{Angle, Microseconds, Millis, Playback};
///
/// let ramp: [Angle; 4] = [0, 1000, 2000, 1000].map(Angle::from_millidegrees);
/// let playback = Playback::new(Millis(160), Microseconds(20_000), 4).unwrap();
/// let mut idle = Player::new(playback, [&ramp, &ramp, &ramp]);
/// assert_eq!(IdleSource::offsets(&mut idle, 3), playback.offsets(3, [&ramp, &ramp, &ramp]));
/// ```
impl<L: LoopSource + ?Sized> IdleSource for Player<'_, L> {
    #[inline]
    fn offsets(&mut self, frame: u64) -> [Angle; 3] {
        Player::offsets(self, frame)
    }
}
