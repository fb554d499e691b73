//! The radar's receiver, board-neutral: what a board's receiver gets from
//! an HLK-LD2450 (bytes at 256000 baud, and receive errors) goes through
//! the core's decoder, and each whole frame's sighting goes to the frame
//! task through the show link (`track`, in [`Links`](crate::boot::Links)): a
//! copy of a few dozen bytes in a critical section, which the frame task
//! takes between two frames. Neither waits for the other.
//!
//! A board calls [`Radar::receive`] on [`RADAR`](crate::boot::RADAR) from
//! its receiver's interrupt or task (on the Pico, a PIO UART on GP13), with
//! the bytes it has, in order, and [`Radar::receive_error`] when bytes were
//! lost (an overrun, a framing error).
//! Another tracker (a camera person sensor on I2C) would be fed the same
//! way through its own `SightingSource`.

use core::cell::RefCell;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use idle_head_core::track::ld2450::Decoder;
use idle_head_core::track::{SightingSource, TrackLink};

/// Feeds `input` (a tracker's raw bytes, in order) to `source`, and the
/// last whole sighting in it, with the counters, to `link` (several in one
/// batch: the older ones are counted as dropped).
pub fn feed(source: &mut impl SightingSource, input: &[u8], link: &TrackLink) {
    let mut latest = None;
    let mut older = 0_u32;
    source.feed(input, &mut |s| {
        if latest.replace(s).is_some() {
            older = older.wrapping_add(1);
        }
    });
    link.publish_after(latest, older, source.counters());
}

/// The LD2450's decoder, for the board's receiver: taken under a critical
/// section, borrowed with `try_borrow_mut` (only the receiver takes it).
pub struct Radar(Mutex<CriticalSectionRawMutex, RefCell<Decoder>>);

impl Radar {
    /// Waiting for the first frame.
    #[must_use]
    pub const fn new() -> Self {
        Self(Mutex::new(RefCell::new(Decoder::new())))
    }

    /// The board's receiver: bytes from the radar, in order; the sighting
    /// goes to `track`.
    pub fn receive(&self, bytes: &[u8], track: &TrackLink) {
        self.0.lock(|cell| {
            if let Ok(mut decoder) = cell.try_borrow_mut() {
                feed(&mut *decoder, bytes, track);
            }
        });
    }

    /// The board's receiver: bytes were lost or damaged here.
    pub fn receive_error(&self, track: &TrackLink) {
        self.0.lock(|cell| {
            if let Ok(mut decoder) = cell.try_borrow_mut() {
                decoder.error();
                track.publish(None, decoder.counters());
            }
        });
    }
}

impl Default for Radar {
    fn default() -> Self {
        Self::new()
    }
}
