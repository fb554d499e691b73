//! Telemetry lines (`watch <hz>`): the head's pose and pulses as the last
//! frame left them, streamed by a port's console task between replies.
//!
//! ```text
//! ~ t=123440 p=-1505 r=-119 y=-236 us=1483,1499,1497 lost=0 *c4
//! ```
//!
//! A line starts with `~`, which no reply starts with (`ok`, `err`, `#`),
//! and ends with the same checksum as a machine-mode reply (CRC-8 of every
//! byte before ` *`), so that a program tells it from a reply and catches
//! a damaged one. `t` is the frame's time in ms since the first frame;
//! `p`, `r`, `y` the commanded angles in mdeg; `us` the pulses written;
//! `lost` the lines this port dropped so far because the host read too
//! slowly (each tick whose line could not go out in time).
//!
//! With the radar on, then `targets` (the people in the radar's latest
//! frame), `at` (the yaw the head aims at while it follows someone, `-`
//! otherwise), `xy` (each person's `x,y` in mm in the radar's frame,
//! `;` between them, in the radar's slot order; `-` for nobody) and `who`
//! (whom the head attends to, an index into `xy` from 0; `-` for nobody,
//! or someone not in this frame):
//!
//! ```text
//! ~ t=123440 p=-1505 r=-119 y=-236 us=1483,1499,1497 lost=0 targets=2 at=-14036 xy=-812,1950;1200,3400 who=0 *3a
//! ```

use crate::text::{Out, Text};

use super::link::HeadStatus;
use super::session::{PORT_REPLY, checksum};
use crate::track::PEOPLE;

/// The longest telemetry line, CR LF included:
/// `~ t=` (4) + 20 digits, ` p=`/` r=`/` y=` 3 × (3 + 11), ` us=` (4) +
/// 3 × 10 + 2 commas, ` lost=` (6) + 10, ` *hh` (4), CR LF (2).
/// With the radar on, ` targets=` (9) + 3 digits, ` at=` (4) + 11,
/// ` xy=` (4) + [`PEOPLE`] × (11 + comma + 11) + a semicolon between two,
/// and ` who=` (5) + 3 digits: 234 bytes in all.
pub const TELEMETRY_LINE: usize =
    4 + 20 + 3 * 14 + 4 + 32 + 6 + 10 + 4 + 2 + 12 + 15 + 4 + PEOPLE * 24 - 1 + 8;

// A port's telemetry line is written into its session's reply buffer.
const _: () = assert!(TELEMETRY_LINE <= PORT_REPLY);

/// The fastest telemetry: one line a frame at 50 Hz.
pub const MAX_WATCH_HZ: u8 = 50;

/// Writes the telemetry line of `status` with `lost` lines dropped so far
/// into `out` (at least [`TELEMETRY_LINE`]
/// bytes: a console writes it into its session's reply buffer, free
/// between replies, [`DualSession::spare`](super::DualSession::spare)); returns
/// the line. (Into a shorter buffer the line is cut, without its end.)
pub fn telemetry_line<'b>(status: &HeadStatus, lost: u32, out: &'b mut [u8]) -> &'b [u8] {
    let mut line = Out::new(out);
    line.text().str("~ t=").u64(status.uptime_ms());
    write_pose(line.text(), status, Angles::Apart);
    line.text().str(" lost=").u64(lost.into());
    if let Some(track) = status.track {
        line.text()
            .str(" targets=")
            .u64(track.targets().into())
            .str(" at=");
        match track.at {
            Some(yaw) => line.text().i64(yaw.millidegrees().into()),
            None => line.text().str("-"),
        };
        line.text().str(" xy=");
        let mut first = true;
        for person in track.seen.people.iter().flatten() {
            if !first {
                line.text().str(";");
            }
            first = false;
            line.text()
                .i64(person.x.0.into())
                .str(",")
                .i64(person.y.0.into());
        }
        if first {
            line.text().str("-");
        }
        line.text().str(" who=");
        match track.who {
            Some(k) => line.text().u64(k.into()),
            None => line.text().str("-"),
        };
    }
    let crc = checksum(line.written());
    line.text().str(" *").hex2(crc).str("\r\n");
    line.into_bytes()
}

/// How a line names the angles of [`write_pose`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Angles {
    /// ` mdeg=<pitch>,<roll>,<yaw>` (`status`).
    Joined,
    /// ` p=<pitch> r=<roll> y=<yaw>` (telemetry).
    Apart,
}

/// Writes the fields `status` and telemetry lines share, from `status`:
/// the commanded angles in mdeg (named as `angles` says), then the pulses
/// written, ` us=<pitch>,<roll>,<yaw>`.
pub(crate) fn write_pose(out: &mut dyn Text, status: &HeadStatus, angles: Angles) {
    let [p, r, y] = status.angles.map(|a| i64::from(a.millidegrees()));
    match angles {
        Angles::Joined => out.str(" mdeg=").i64(p).str(",").i64(r).str(",").i64(y),
        Angles::Apart => out.str(" p=").i64(p).str(" r=").i64(r).str(" y=").i64(y),
    };
    let [pp, pr, py] = status.pulses.map(|us| u64::from(us.0));
    out.str(" us=").u64(pp).str(",").u64(pr).str(",").u64(py);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::console::HeadMode;
    use crate::track::{Person, Sighting, TrackView};
    use crate::units::{Angle, Microseconds, Millimetres};

    fn person(x: i32, y: i32) -> Person {
        Person {
            x: Millimetres(x),
            y: Millimetres(y),
        }
    }

    #[test]
    fn a_line_reads_back_and_the_longest_fits() {
        let mut out = [0; TELEMETRY_LINE];
        let status = HeadStatus {
            frame: 50,
            time: crate::Timestamp(1_000_000),
            mode: HeadMode::Running,
            angles: [-1505, -119, 236].map(Angle::from_millidegrees),
            pulses: [1483, 1499, 1497].map(Microseconds),
            faults: [0; 3],
            disabled: [false; 3],
            track: None,
            idle: None,
        };
        let line = telemetry_line(&status, 3, &mut out).to_vec();
        let text = std::str::from_utf8(&line).unwrap();
        let (body, tail) = text.rsplit_once(" *").unwrap();
        assert_eq!(
            body,
            "~ t=1000 p=-1505 r=-119 y=236 us=1483,1499,1497 lost=3"
        );
        assert_eq!(tail, format!("{:02x}\r\n", checksum(body.as_bytes())));

        // The radar's people in slot order, the empty slot left out; `who`
        // counts among those listed.
        let radar = HeadStatus {
            track: Some(TrackView {
                seen: Sighting {
                    people: [Some(person(-812, 1950)), None, Some(person(1200, 3400))],
                },
                who: Some(1),
                at: Some(Angle::from_millidegrees(-14_036)),
            }),
            ..status
        };
        let line = telemetry_line(&radar, 3, &mut out).to_vec();
        assert!(
            String::from_utf8_lossy(&line)
                .contains(" lost=3 targets=2 at=-14036 xy=-812,1950;1200,3400 who=1 *"),
            "{}",
            String::from_utf8_lossy(&line)
        );
        let nobody = HeadStatus {
            track: Some(TrackView::default()),
            ..status
        };
        let line = telemetry_line(&nobody, 0, &mut out).to_vec();
        assert!(String::from_utf8_lossy(&line).contains(" lost=0 targets=0 at=- xy=- who=- *"));

        // Every field at its longest: the line end whole, and the bound
        // exact but for the time, whose 20 digits are a u64's (the ms of
        // u64::MAX µs have 17), and `targets`, whose 3 are a u8's (a
        // sighting holds at most 3 people: 1 digit).
        let far = Some(person(i32::MIN, i32::MIN));
        let worst = HeadStatus {
            frame: u64::MAX,
            time: crate::Timestamp(u64::MAX),
            angles: [Angle::from_millidegrees(i32::MIN); 3],
            pulses: [Microseconds(u32::MAX); 3],
            track: Some(TrackView {
                seen: Sighting {
                    people: [far; crate::track::PEOPLE],
                },
                who: Some(u8::MAX),
                at: Some(Angle::from_millidegrees(i32::MIN)),
            }),
            ..status
        };
        let line = telemetry_line(&worst, u32::MAX, &mut out);
        assert!(line.ends_with(b"\r\n"), "{}", String::from_utf8_lossy(line));
        assert_eq!(
            line.len(),
            TELEMETRY_LINE - 3 - 2,
            "{}",
            String::from_utf8_lossy(line)
        );
    }
}
