//! The personality: what each of the head's slots means (table in the
//! [module docs](super)).

use crate::gestures::GestureKind;

use super::FOOTPRINT;

/// One good frame's slots, taken apart.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cue {
    /// Yaw, pitch and roll, 16 bit each (coarse · 256 + fine), `[pitch,
    /// roll, yaw]`: 0 is the axis' lower angle limit, 65 535 its upper.
    pub pose: [u16; 3],
    /// Position mix, 0 (the head's own motion) to 255 (the DMX pose).
    pub mix: u8,
    /// The gesture trigger's value ([`Trigger::of`]).
    pub trigger: u8,
    /// Idle intensity, 0 to 255.
    pub intensity: u8,
}

impl Cue {
    /// Every slot at 0.
    pub const ZERO: Self = Self {
        pose: [0; 3],
        mix: 0,
        trigger: 0,
        intensity: 0,
    };

    /// The cue of a frame's personality slots (slot 10, reserved, is not
    /// read).
    #[must_use]
    pub const fn from_slots(s: &[u8; FOOTPRINT as usize]) -> Self {
        Self {
            pose: [wide(s[2], s[3]), wide(s[4], s[5]), wide(s[0], s[1])],
            mix: s[6],
            trigger: s[7],
            intensity: s[8],
        }
    }

    /// The idle intensity as a percentage: 0–255 → 0–100 %, rounded.
    #[must_use]
    pub const fn intensity_percent(&self) -> u8 {
        ((self.intensity as u16 * 100 + 127) / 255) as u8
    }
}

/// A 16-bit slot pair: coarse, fine.
const fn wide(coarse: u8, fine: u8) -> u16 {
    (coarse as u16) << 8 | fine as u16
}

/// The gesture trigger's bands (slot 8), [`BAND`] values wide: one per
/// gesture of the table ([`GestureKind::ALL`]), in its order, from 10 on,
/// around the centre's band (70–89, where it always was). A gesture fires
/// when the slot enters its band, and not again until the slot has left it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Trigger {
    /// Below 10, and above the last gesture's band: nothing.
    None,
    /// A gesture's band (10–29 nod, 30–49 shake, 50–69 tilt, then from 90
    /// on the gestures after them).
    Gesture(GestureKind),
    /// 70–89: back to the centre.
    Center,
}

/// The width of a band.
pub const BAND: u8 = 20;
/// Where the first gesture's band starts.
const FIRST: u8 = 10;
/// Where the centre's band starts.
const CENTER: u8 = 70;

/// How many gestures the bands have room for: up to 255 past the centre's.
const ROOM: usize = ((u8::MAX - FIRST + 1 - BAND) / BAND) as usize;
const _: () = assert!(
    GestureKind::ALL.len() <= ROOM,
    "the DMX trigger slot is full: a gesture past the eleventh has no band"
);

impl Trigger {
    /// The band `value` lies in.
    #[must_use]
    pub const fn of(value: u8) -> Self {
        if value >= CENTER && value < CENTER + BAND {
            return Self::Center;
        }
        if value < FIRST {
            return Self::None;
        }
        // The bands as if the centre's were not there.
        let packed = if value >= CENTER { value - BAND } else { value };
        let index = ((packed - FIRST) / BAND) as usize;
        if index < GestureKind::ALL.len() {
            Self::Gesture(GestureKind::ALL[index])
        } else {
            Self::None
        }
    }

    /// The values of gesture `kind`'s band.
    #[must_use]
    pub const fn band(kind: GestureKind) -> core::ops::RangeInclusive<u8> {
        let mut index = 0;
        while index < GestureKind::ALL.len() && GestureKind::ALL[index] as u8 != kind as u8 {
            index += 1;
        }
        // `ROOM` bands fit: the start stays below 255 - BAND.
        let start = FIRST + BAND * index as u8;
        let start = if start >= CENTER { start + BAND } else { start };
        start..=start + (BAND - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_in_the_order_of_the_table() {
        let cue = Cue::from_slots(&[0xc8, 0x01, 0x12, 0x34, 0x56, 0x78, 255, 20, 128, 99]);
        assert_eq!(cue.pose, [0x1234, 0x5678, 0xc801]);
        assert_eq!((cue.mix, cue.trigger, cue.intensity), (255, 20, 128));
        assert_eq!(cue.intensity_percent(), 50);
        let full = Cue {
            intensity: 255,
            ..cue
        };
        assert_eq!(full.intensity_percent(), 100);
    }

    #[test]
    fn bands_and_their_edges() {
        use Trigger::{Center, Gesture, None};
        let (nod, shake, tilt) = (
            Gesture(GestureKind::Nod),
            Gesture(GestureKind::Shake),
            Gesture(GestureKind::Tilt),
        );
        let bands: Vec<Trigger> = [0, 9, 10, 29, 30, 49, 50, 69, 70, 89, 90, 255]
            .map(Trigger::of)
            .to_vec();
        assert_eq!(
            bands,
            [
                None, None, nod, nod, shake, shake, tilt, tilt, Center, Center, None, None
            ]
        );
    }

    /// Every gesture of the table has a band of its own, and every value
    /// of a band fires its gesture.
    #[test]
    fn every_gesture_has_its_band() {
        let mut seen = Vec::new();
        for kind in GestureKind::ALL {
            let band = Trigger::band(kind);
            assert_eq!(band.end() - band.start(), BAND - 1);
            for value in band.clone() {
                assert_eq!(Trigger::of(value), Trigger::Gesture(kind), "{value}");
            }
            assert!(!(70..=89).contains(band.start()));
            seen.push(band);
        }
        assert_eq!(seen.len(), GestureKind::ALL.len());
        assert_eq!(Trigger::band(GestureKind::Nod), 10..=29);
        assert_eq!(Trigger::band(GestureKind::Tilt), 50..=69);
    }
}
