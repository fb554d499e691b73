//! The tracker's hold on the gaze: moves that follow a person, and the
//! gaze given back to the centre.

use crate::axis::Axis;
use crate::units::{Angle, Millis};

use super::super::gaze::By;
use super::super::rest::RestState;
use super::Mixer;

impl Mixer {
    /// Whether the tracker may move the gaze now: no look holds it (a
    /// look's return frees it) and the head neither rests nor goes to
    /// rest.
    pub(crate) fn gaze_free(&self) -> bool {
        self.gaze.by() != By::Look && !matches!(self.rest.state(), RestState::Resting)
    }

    /// Whether the gaze is where the tracker last put it.
    pub(crate) fn gaze_tracked(&self) -> bool {
        self.gaze.by() == By::Track
    }

    /// The tracker's move to `target` (`[pitch, yaw]`, axis angles, held
    /// to the servos' limits) from the next frame on, in `given` or the
    /// look's time for the distance; the idle ducked as under a held look.
    pub(crate) fn follow(&mut self, target: [Angle; 2], given: Option<Millis>) {
        let offsets = [
            self.params.offset_within(Axis::Pitch, target[0]).0,
            self.params.offset_within(Axis::Yaw, target[1]).0,
        ]
        .map(Angle::millidegrees);
        let next = self.next;
        self.gaze.follow(&self.params, next, offsets, given);
        self.gazing();
        self.moved(next);
    }

    /// The tracker lets go: the gaze returns to the centre in the look's
    /// time for the distance (the idle's duck fades along).
    pub(crate) fn unfollow(&mut self) {
        let next = self.next;
        // No given duration: never refused.
        let _ = self.gaze.center(&self.params, next, None);
        self.gazing();
        self.moved(next);
    }

    /// A move starts at `next`: mixed in full from there.
    fn moved(&mut self, next: u32) {
        self.quiet = false;
        self.until = next;
        self.schedule(next);
    }
}
