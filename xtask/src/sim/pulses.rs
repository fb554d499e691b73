//! Checks one servo's pulse train from the emulator against the duties the
//! host computes, frame for frame: each pulse carries the duty of the last
//! compare write before its rise, and the pulse of PWM period `n` must
//! carry frame `n` (at the run's servo rate: a late or lost frame shows as a pulse carrying another;
//! pulses after the last frame repeat it and count as held). Why the
//! periods map to frames so: docs/dev/emulators.md.

use idle_head_core::driver::DriverConfig;

/// The angle, m°, of a pulse of `width` ns on `axis`' servo (the built-in
/// calibration).
pub fn angle(axis: usize, width: f64) -> f64 {
    let servo = DriverConfig::DEFAULT.servos[axis];
    let neutral = f64::from(servo.neutral.0) * 1e3;
    (width - neutral) / f64::from(servo.per_degree.0) * 1e3
}

/// PWM timing of a slice.
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    /// One counter step, in nanoseconds.
    pub count_ns: f64,
    /// Counts per period (`TOP + 1`).
    pub period_counts: u32,
    /// The frame period, ns: the PWM period must be within one count of it.
    pub frame_ns: f64,
}

impl Timing {
    fn period_ns(&self) -> f64 {
        f64::from(self.period_counts) * self.count_ns
    }
}

/// A servo's duties that matter to the check, in counts.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// The neutral pulse: the first pulse must be this.
    pub neutral: u16,
    pub min: u16,
    pub max: u16,
}

/// What the emulator reported for one servo during one boot.
#[derive(Debug, Clone, Default)]
pub struct Train {
    /// Pin level changes `(ns, high)`, in order.
    pub edges: Vec<(f64, bool)>,
    /// Compare writes of the servo's channel `(ns, counts)`, in order.
    pub writes: Vec<(f64, u16)>,
    /// When the slice was enabled.
    pub enabled: Option<f64>,
    pub end: f64,
    /// Whether a reset ended it (a pulse then in flight was cut).
    pub reset: bool,
}

/// One complete pulse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pulse {
    pub rise: f64,
    pub counts: u32,
    /// The frame whose duty it carried.
    pub frame: usize,
}

/// One complete pulse on a pin, as measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Rising edge, ns since power-on.
    pub rise: f64,
    pub width: f64,
}

/// The complete pulses of `train` from `from` (ns) on: each a rise and the
/// fall after it. A pulse still high at the end is left out.
pub fn spans(train: &Train, from: f64) -> Vec<Measured> {
    let mut rise = None;
    let mut out = Vec::new();
    for &(t, high) in train.edges.iter().filter(|&&(t, _)| t >= from) {
        match (high, rise) {
            (true, None) => rise = Some(t),
            (false, Some(r)) => {
                out.push(Measured {
                    rise: r,
                    width: t - r,
                });
                rise = None;
            }
            _ => {}
        }
    }
    out
}

/// The complete pulses of `train` from the slice's enable on, for the
/// checks that look at the pulses themselves (show control, the latency
/// rows, the CSV of `--pulses`).
pub fn measure(train: &Train) -> Vec<Measured> {
    spans(train, train.enabled.unwrap_or(f64::INFINITY))
}

/// The verdict on one servo's train.
#[derive(Debug, Clone, Default)]
pub struct ServoCheck {
    pub pulses: Vec<Pulse>,
    pub frames: usize,
    /// Pulses that carried their own frame (pulse `n`, frame `n`).
    pub fresh: usize,
    /// Pulses after the last frame, repeating its duty.
    pub held: usize,
    /// Whether a pulse was cut short by a reset.
    pub cut: bool,
    /// Frames whose written duty or pulse differs from the host's.
    pub mismatches: usize,
    /// Shortest and longest period, rising edge to rising edge, ns.
    pub periods: Option<(f64, f64)>,
    /// What is wrong, one sentence each (the first few of each kind).
    pub problems: Vec<String>,
}

/// At most this many messages of one kind; the rest are counted.
const SHOWN: usize = 3;

/// Collects problems of one kind, keeping the first few.
#[derive(Default)]
struct Kind {
    shown: Vec<String>,
    count: usize,
}

impl Kind {
    fn push(&mut self, message: impl FnOnce() -> String) {
        if self.shown.len() < SHOWN {
            self.shown.push(message());
        }
        self.count += 1;
    }

    fn drain_into(self, problems: &mut Vec<String>, what: &str) {
        let more = self.count - self.shown.len();
        problems.extend(self.shown);
        if more > 0 {
            problems.push(format!("... and {more} more {what}"));
        }
    }
}

/// Checks `train` against `expected` (the host's duty for each frame, from
/// frame 0; at least as many as were written).
#[allow(clippy::too_many_lines)] // one pass over the train, in the order of the module docs
pub fn check(train: &Train, expected: &[u16], timing: &Timing, limits: Limits) -> ServoCheck {
    let mut out = ServoCheck::default();
    let ms = |ns: f64| ns / 1e6;
    let Some(enabled) = train.enabled else {
        if train.edges.iter().any(|&(_, high)| high) {
            out.problems
                .push("pulses on a slice that was never enabled".to_owned());
        } else {
            out.problems
                .push("the slice was never enabled: no frame".to_owned());
        }
        return out;
    };
    // Frame 0 is the compare write just before the enable; the rest follow.
    let Some(first) = train.writes.iter().rposition(|&(t, _)| t <= enabled) else {
        out.problems
            .push("the slice was enabled before any duty was written".to_owned());
        return out;
    };
    let frames = &train.writes[first..];
    out.frames = frames.len();
    if expected.len() < frames.len() {
        out.problems.push(format!(
            "{} frames written but only {} expected from the host",
            frames.len(),
            expected.len()
        ));
        return out;
    }
    let start = frames[0].0;
    if let Some(&(t, _)) = train.edges.iter().find(|&&(t, high)| high && t < start) {
        out.problems.push(format!(
            "a rising edge at {:.3} ms, before the first frame ({:.3} ms)",
            ms(t),
            ms(start)
        ));
    }

    let spans = spans(train, start);
    // A pulse still high at the end (the last edge a rise) was cut.
    out.cut = train.reset
        && train
            .edges
            .iter()
            .rfind(|&&(t, _)| t >= start)
            .is_some_and(|&(_, high)| high);

    let (mut wrong_frame, mut wrong_duty, mut wrong_width) =
        (Kind::default(), Kind::default(), Kind::default());
    let (mut outside, mut bad_period) = (Kind::default(), Kind::default());
    let mut mismatched = vec![false; frames.len()];
    let first_rise = spans.first().map_or(0.0, |p| p.rise);
    let mut last_period = None;
    for &Measured { rise: r, width } in &spans {
        // The period this pulse went out in (pulse `n` of a train without
        // gaps).
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // a period count, ≥ 0
        let n = ((r - first_rise) / timing.period_ns()).round().max(0.0) as usize;
        // The duty latched at this rise: the last write before it.
        let latched = frames.partition_point(|&(t, _)| t < r);
        let Some(frame) = latched.checked_sub(1) else {
            continue; // a rise before frame 0 was reported above
        };
        let counts = (width / timing.count_ns).round();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // a width, < 2^16
        let counts = counts.max(0.0) as u32;
        out.pulses.push(Pulse {
            rise: r,
            counts,
            frame,
        });
        if frame == n {
            out.fresh += 1;
        } else if frame + 1 == frames.len() && n > frame {
            out.held += 1;
        } else {
            wrong_frame.push(|| {
                format!(
                    "pulse {n} at {:.3} ms carries frame {frame}: a frame {} before it",
                    ms(r),
                    if frame < n {
                        "was late or lost"
                    } else {
                        "came twice"
                    }
                )
            });
        }
        let want = expected[frame];
        let written = frames[frame].1;
        if written != want && !mismatched[frame] {
            mismatched[frame] = true;
            wrong_duty.push(|| format!("frame {frame}: wrote {written} counts, the host {want}"));
        }
        if counts.abs_diff(u32::from(want)) > 1 {
            if !mismatched[frame] {
                mismatched[frame] = true;
            }
            wrong_width.push(|| {
                format!(
                    "pulse {n} (frame {frame}) at {:.3} ms: {counts} counts, the host {want}",
                    ms(r)
                )
            });
        }
        if counts + 1 < u32::from(limits.min) || counts > u32::from(limits.max) + 1 {
            outside.push(|| {
                format!(
                    "pulse {n} at {:.3} ms: {counts} counts, outside the servo's [{}, {}]",
                    ms(r),
                    limits.min,
                    limits.max
                )
            });
        }
        if let Some((k, previous)) = last_period
            && n == k + 1
        {
            let period = r - previous;
            let (low, high) = out.periods.unwrap_or((period, period));
            out.periods = Some((low.min(period), high.max(period)));
            for want in [timing.period_ns(), timing.frame_ns] {
                if (period - want).abs() > timing.count_ns {
                    bad_period.push(|| {
                        format!("period before pulse {n}: {period:.1} ns, not {want:.1} ns within one count")
                    });
                }
            }
        }
        last_period = Some((n, r));
    }
    // Frames written with duty 0 (no pulse) that the host also gave 0.
    for (frame, &(_, duty)) in frames.iter().enumerate() {
        if duty == 0 && expected[frame] != 0 && !mismatched[frame] {
            mismatched[frame] = true;
            let want = expected[frame];
            wrong_duty.push(|| format!("frame {frame}: wrote 0 counts, the host {want}"));
        }
    }
    out.mismatches = mismatched.iter().filter(|&&m| m).count();

    if let Some(first) = out.pulses.first()
        && first.counts.abs_diff(u32::from(limits.neutral)) > 1
    {
        out.problems.push(format!(
            "the first pulse is {} counts, not the neutral {}",
            first.counts, limits.neutral
        ));
    }
    // Every frame written early enough to be latched and finished before the
    // boot ended must have had its pulse (but for one written with duty 0).
    let finished = |&&(t, duty): &&(f64, u16)| {
        duty != 0 && t + timing.period_ns() + f64::from(limits.max) * timing.count_ns < train.end
    };
    let due = frames.iter().filter(finished).count();
    if out.fresh < due {
        out.problems.push(format!(
            "{} frames were due to go out before the end, {} pulses carried one",
            due, out.fresh
        ));
    }
    wrong_frame.drain_into(&mut out.problems, "pulses carrying the wrong frame");
    wrong_duty.drain_into(
        &mut out.problems,
        "frames written with another duty than the host's",
    );
    wrong_width.drain_into(
        &mut out.problems,
        "pulses of another width than the host's duty",
    );
    outside.drain_into(&mut out.problems, "pulses outside the servo's limits");
    bad_period.drain_into(&mut out.problems, "periods off by more than one count");
    out
}

#[cfg(test)]
#[allow(clippy::cast_precision_loss, clippy::cast_possible_truncation)] // small test numbers
mod tests {
    use super::*;

    const TIMING: Timing = Timing {
        count_ns: 312.5,
        period_counts: 64_000,
        frame_ns: 20e6,
    };
    const LIMITS: Limits = Limits {
        neutral: 4800,
        min: 3200,
        max: 6400,
    };

    /// The train the emulator gives for `duties`: frame k written at
    /// `k · 20 ms + 150 µs` (frame 0 at 0, enabling the slice half a period
    /// in), pulse n rising at `(n + ½) · P`.
    fn train(duties: &[u16], end: f64) -> Train {
        let period = TIMING.period_ns();
        let mut t = Train {
            writes: vec![(-1000.0, 0)],
            enabled: Some(10.0),
            end,
            ..Train::default()
        };
        for (k, &duty) in duties.iter().enumerate() {
            let written = if k == 0 { 0.0 } else { k as f64 * 20e6 + 150e3 };
            t.writes.push((written, duty));
            let rise = (k as f64 + 0.5) * period + 10.0;
            if rise + f64::from(duty) * TIMING.count_ns < end {
                t.edges.push((rise, true));
                t.edges
                    .push((rise + f64::from(duty) * TIMING.count_ns, false));
            }
        }
        t
    }

    fn ramp(frames: usize) -> Vec<u16> {
        (0..frames).map(|k| 4800 + (k as u16 % 50) * 7).collect()
    }

    #[test]
    fn a_train_equal_to_the_host_passes() {
        let duties = ramp(100);
        let check = check(
            &train(&duties, 100.0 * 20e6 + 5e6),
            &duties,
            &TIMING,
            LIMITS,
        );
        assert!(check.problems.is_empty(), "{:?}", check.problems);
        assert_eq!((check.fresh, check.held, check.mismatches), (100, 0, 0));
        let (low, high) = check.periods.unwrap();
        assert!((low - 20e6).abs() < 1.0 && (high - 20e6).abs() < 1.0);
    }

    #[test]
    fn a_wrong_expectation_fails() {
        let duties = ramp(100);
        let mut wrong = duties.clone();
        wrong[40] += 2;
        let check = check(&train(&duties, 100.0 * 20e6 + 5e6), &wrong, &TIMING, LIMITS);
        assert_eq!(check.mismatches, 1);
        assert!(
            check
                .problems
                .iter()
                .any(|p| p.starts_with("frame 40: wrote"))
        );
        assert!(
            check
                .problems
                .iter()
                .any(|p| p.starts_with("pulse 40 (frame 40)"))
        );
    }

    #[test]
    fn a_lost_frame_fails_even_where_the_duty_is_flat() {
        let duties = vec![4800; 60];
        let mut t = train(&duties, 60.0 * 20e6 + 5e6);
        t.writes.remove(31); // frame 30 never written
        let check = check(&t, &duties, &TIMING, LIMITS);
        assert_eq!(check.mismatches, 0);
        assert!(
            check.problems.iter().any(|p| p.contains("carries frame")),
            "{:?}",
            check.problems
        );
    }

    #[test]
    fn early_edges_wrong_first_pulse_limits_and_periods_fail() {
        let duties: Vec<u16> = (0..20).map(|k| if k == 0 { 5000 } else { 7000 }).collect();
        let mut t = train(&duties, 20.0 * 20e6 + 5e6);
        t.edges.insert(0, (-500.0, true));
        t.edges.insert(1, (-400.0, false));
        if let Some(edge) = t.edges.iter_mut().rev().find(|e| e.1) {
            edge.0 += 2000.0; // the last period 2 µs long
        }
        let problems = check(&t, &duties, &TIMING, LIMITS).problems.join("\n");
        for part in [
            "before the first frame",
            "not the neutral",
            "outside the servo",
            "not 20000000.0 ns",
        ] {
            assert!(problems.contains(part), "no `{part}` in\n{problems}");
        }
    }

    #[test]
    fn frames_of_duty_0_leave_their_periods_empty() {
        // Frames 20 to 39 relaxed (duty 0: no pulse), then pulses again.
        let duties: Vec<u16> = (0..60)
            .map(|k| if (20..40).contains(&k) { 0 } else { 4800 + k })
            .collect();
        let mut t = train(&duties, 60.0 * 20e6 + 5e6);
        t.edges.retain(|&(ns, _)| {
            !(20.4 * TIMING.period_ns()..40.0 * TIMING.period_ns()).contains(&ns)
        });
        let check = check(&t, &duties, &TIMING, LIMITS);
        assert!(check.problems.is_empty(), "{:?}", check.problems);
        assert_eq!((check.fresh, check.mismatches), (40, 0));
        // The host wanted pulses there: every frame of the gap is named.
        let mut wanted = duties.clone();
        wanted[25] = 4800;
        let check = check_wanted(&t, &wanted);
        assert!(
            check
                .problems
                .iter()
                .any(|p| p.contains("frame 25: wrote 0 counts")),
            "{:?}",
            check.problems
        );
    }

    #[test]
    fn spans_from_a_time_on_without_the_one_still_high() {
        let train = Train {
            edges: vec![
                (5.0, true),
                (15.0, false), // began before `from`: its fall alone
                (20.0, true),
                (21.0, true), // no fall between: one pulse
                (30.0, false),
                (40.0, true), // still high at the end
            ],
            enabled: Some(10.0),
            ..Train::default()
        };
        let whole = Measured {
            rise: 20.0,
            width: 10.0,
        };
        assert_eq!(measure(&train), vec![whole]);
        let from_0 = spans(&train, 0.0);
        let early = Measured {
            rise: 5.0,
            width: 10.0,
        };
        assert_eq!(from_0, vec![early, whole]);
        assert!(measure(&Train::default()).is_empty());
    }

    fn check_wanted(t: &Train, wanted: &[u16]) -> ServoCheck {
        check(t, wanted, &TIMING, LIMITS)
    }

    #[test]
    fn frames_stopping_before_a_reset_hold_the_last_duty() {
        let duties = ramp(30);
        let mut t = train(&duties, 36.0 * 20e6);
        let period = TIMING.period_ns();
        for n in 30..35 {
            let rise = (f64::from(n) + 0.5) * period + 10.0;
            t.edges.push((rise, true));
            t.edges
                .push((rise + f64::from(duties[29]) * TIMING.count_ns, false));
        }
        t.edges.push((35.5 * period + 10.0, true)); // cut by the reset
        t.reset = true;
        let check = check(&t, &duties, &TIMING, LIMITS);
        assert!(check.problems.is_empty(), "{:?}", check.problems);
        assert_eq!((check.fresh, check.held, check.cut), (30, 5, true));
    }
}
