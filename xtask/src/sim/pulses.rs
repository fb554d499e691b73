//! Checks one servo's pulse train from the emulator against the host's
//! duties, frame for frame: a pulse carries the last compare write before
//! its rise, and the pulse of PWM period `n` must carry frame `n` (pulses
//! after the last frame repeat it, held). Why: docs/dev/emulators.md.

use idle_head_core::driver::DriverConfig;

/// The angle, m°, of a pulse of `width` ns on `axis`' servo.
pub fn angle(axis: usize, width: f64) -> f64 {
    let servo = DriverConfig::DEFAULT.servos[axis];
    let neutral = f64::from(servo.neutral.0) * 1e3;
    (width - neutral) / f64::from(servo.per_degree.0) * 1e3
}

/// PWM timing of a slice: one count, ns; counts a period (`TOP + 1`); the
/// frame period, ns, which the PWM period must match within a count.
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    pub count_ns: f64,
    pub period_counts: u32,
    pub frame_ns: f64,
}

impl Timing {
    pub fn period_ns(&self) -> f64 {
        f64::from(self.period_counts) * self.count_ns
    }
}

/// A servo's neutral (the first pulse), shortest and longest duty, counts.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    pub neutral: u16,
    pub min: u16,
    pub max: u16,
}

/// What the emulator reported for one servo in one boot: pin edges
/// `(ns, high)` and compare writes `(ns, counts)` in order, when the slice
/// was enabled, when the boot ended.
#[derive(Debug, Clone, Default)]
pub struct Train {
    pub edges: Vec<(f64, bool)>,
    pub writes: Vec<(f64, u16)>,
    pub enabled: Option<f64>,
    pub end: f64,
}

/// One complete pulse and the frame whose duty it carried.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pulse {
    pub rise: f64,
    pub counts: u32,
    pub frame: usize,
}

/// One complete pulse on a pin as measured: rise (ns since power-on), width.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    pub rise: f64,
    pub width: f64,
}

impl Train {
    /// The compare writes from frame 0 (the write just before the enable).
    pub fn frames(&self) -> Option<&[(f64, u16)]> {
        let enabled = self.enabled?;
        let first = self.writes.iter().rposition(|&(t, _)| t <= enabled)?;
        Some(&self.writes[first..])
    }
}

/// The complete pulses of `train` from `from` (ns) on; one still high at the
/// end is left out.
pub fn spans(train: &Train, from: f64) -> Vec<Measured> {
    let (mut rise, mut out) = (None, Vec::new());
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

/// The complete pulses of `train` from the slice's enable on.
pub fn measure(train: &Train) -> Vec<Measured> {
    spans(train, train.enabled.unwrap_or(f64::INFINITY))
}

/// The verdict on one servo's train.
#[derive(Debug, Clone, Default)]
pub struct ServoCheck {
    pub pulses: Vec<Pulse>,
    pub frames: usize,
    /// Pulses carrying their own frame (pulse `n`, frame `n`); pulses after
    /// the last frame, repeating it.
    pub fresh: usize,
    pub held: usize,
    /// Frames whose written duty or pulse differs from the host's.
    pub mismatches: usize,
    /// Shortest and longest period, rise to rise, ns.
    pub periods: Option<(f64, f64)>,
    /// What is wrong, the first few of each kind.
    pub problems: Vec<String>,
}

/// At most this many messages of one kind; the rest are counted.
const SHOWN: usize = 3;

/// Checks `train` against `expected` (the host's duty for each frame from
/// frame 0, at least as many as were written).
#[allow(clippy::too_many_lines)] // one pass over the train
pub fn check(train: &Train, expected: &[u16], timing: &Timing, limits: Limits) -> ServoCheck {
    let (mut out, ms) = (ServoCheck::default(), |ns: f64| ns / 1e6);
    let Some(frames) = train.frames() else {
        let problem = match train.enabled {
            Some(_) => "the slice was enabled before any duty was written",
            None if train.edges.iter().any(|&(_, high)| high) => {
                "pulses on a slice that was never enabled"
            }
            None => "the slice was never enabled: no frame",
        };
        out.problems.push(problem.to_owned());
        return out;
    };
    out.frames = frames.len();
    if expected.len() < frames.len() {
        let (n, host) = (frames.len(), expected.len());
        out.problems.push(format!(
            "{n} frames written but only {host} expected from the host"
        ));
        return out;
    }
    let start = frames[0].0;
    if let Some(&(t, _)) = train.edges.iter().find(|&&(t, high)| high && t < start) {
        let (t, start) = (ms(t), ms(start));
        let problem = format!("a rising edge at {t:.3} ms, before the first frame ({start:.3} ms)");
        out.problems.push(problem);
    }
    let spans = spans(train, start);
    // Wrong frame, wrong duty, wrong width, outside the limits, bad period.
    let mut kinds: [Vec<String>; 5] = Default::default();
    let mut mismatched = vec![false; frames.len()];
    let first_rise = spans.first().map_or(0.0, |p| p.rise);
    let mut last_period = None;
    for &Measured { rise: r, width } in &spans {
        // The period this pulse went out in (pulse `n` of a train without gaps).
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // a period count, ≥ 0
        let n = ((r - first_rise) / timing.period_ns()).round().max(0.0) as usize;
        // The duty latched at this rise: the last write before it.
        let Some(frame) = frames.partition_point(|&(t, _)| t < r).checked_sub(1) else {
            continue; // a rise before frame 0 was reported above
        };
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // a width, < 2^16
        let counts = (width / timing.count_ns).round().max(0.0) as u32;
        let at = ms(r);
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
            let why = if frame < n {
                "was late or lost"
            } else {
                "came twice"
            };
            kinds[0].push(format!(
                "pulse {n} at {at:.3} ms carries frame {frame}: a frame {why} before it"
            ));
        }
        let want = expected[frame];
        if counts.abs_diff(u32::from(want)) > 1 {
            mismatched[frame] = true;
            kinds[2].push(format!(
                "pulse {n} (frame {frame}) at {at:.3} ms: {counts} counts, the host {want}"
            ));
        }
        if counts + 1 < u32::from(limits.min) || counts > u32::from(limits.max) + 1 {
            let (min, max) = (limits.min, limits.max);
            kinds[3].push(format!(
                "pulse {n} at {at:.3} ms: {counts} counts, outside the servo's [{min}, {max}]"
            ));
        }
        if let Some((k, previous)) = last_period
            && n == k + 1
        {
            let period = r - previous;
            let (low, high) = out.periods.unwrap_or((period, period));
            out.periods = Some((low.min(period), high.max(period)));
            for want in [timing.period_ns(), timing.frame_ns] {
                if (period - want).abs() > timing.count_ns {
                    kinds[4].push(format!(
                        "period before pulse {n}: {period:.1} ns, not {want:.1} ns within one count"
                    ));
                }
            }
        }
        last_period = Some((n, r));
    }
    // Every frame's written duty, whether a pulse carried it or not (duty 0).
    for (frame, (&(_, written), &want)) in frames.iter().zip(expected).enumerate() {
        if written != want {
            mismatched[frame] = true;
            kinds[1].push(format!(
                "frame {frame}: wrote {written} counts, the host {want}"
            ));
        }
    }
    out.mismatches = mismatched.iter().filter(|&&m| m).count();
    if let Some(first) = out.pulses.first()
        && first.counts.abs_diff(u32::from(limits.neutral)) > 1
    {
        let (counts, neutral) = (first.counts, limits.neutral);
        let problem = format!("the first pulse is {counts} counts, not the neutral {neutral}");
        out.problems.push(problem);
    }
    // Every frame written early enough to be latched and finished before the
    // boot ended must have had its pulse (but for one of duty 0).
    let finished = |&&(t, duty): &&(f64, u16)| {
        duty != 0 && t + timing.period_ns() + f64::from(limits.max) * timing.count_ns < train.end
    };
    let due = frames.iter().filter(finished).count();
    if out.fresh < due {
        let fresh = out.fresh;
        let problem =
            format!("{due} frames were due to go out before the end, {fresh} pulses carried one");
        out.problems.push(problem);
    }
    let whats = [
        "pulses carrying the wrong frame",
        "frames written with another duty than the host's",
        "pulses of another width than the host's duty",
        "pulses outside the servo's limits",
        "periods off by more than one count",
    ];
    for (found, what) in kinds.into_iter().zip(whats) {
        let more = found.len().saturating_sub(SHOWN);
        out.problems.extend(found.into_iter().take(SHOWN));
        if more > 0 {
            out.problems.push(format!("... and {more} more {what}"));
        }
    }
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

    /// `train` checked against `wanted`; its problems as one text.
    fn run(train: &Train, wanted: &[u16]) -> (ServoCheck, String) {
        let check = check(train, wanted, &TIMING, LIMITS);
        let problems = check.problems.join("\n");
        (check, problems)
    }

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
            let fall = rise + f64::from(duty) * TIMING.count_ns;
            if fall < end {
                t.edges.extend([(rise, true), (fall, false)]);
            }
        }
        t
    }

    fn ramp(frames: usize) -> Vec<u16> {
        (0..frames).map(|k| 4800 + (k as u16 % 50) * 7).collect()
    }

    #[test]
    fn a_train_equal_to_the_host_passes_and_one_duty_off_fails() {
        let duties = ramp(100);
        let train = train(&duties, 100.0 * 20e6 + 5e6);
        let (check, problems) = run(&train, &duties);
        assert!(problems.is_empty(), "{problems}");
        assert_eq!((check.fresh, check.held, check.mismatches), (100, 0, 0));
        let (low, high) = check.periods.unwrap();
        assert!((low - 20e6).abs() < 1.0 && (high - 20e6).abs() < 1.0);
        let mut wrong = duties.clone();
        wrong[40] += 2;
        let (check, problems) = run(&train, &wrong);
        assert_eq!(check.mismatches, 1);
        assert!(problems.contains("frame 40: wrote") && problems.contains("pulse 40 (frame 40)"));
    }

    #[test]
    fn a_lost_frame_fails_even_where_the_duty_is_flat() {
        let duties = vec![4800; 60];
        let mut t = train(&duties, 60.0 * 20e6 + 5e6);
        t.writes.remove(31); // frame 30 never written
        let (check, problems) = run(&t, &duties);
        assert_eq!(check.mismatches, 0);
        assert!(problems.contains("carries frame"), "{problems}");
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
        let (_, problems) = run(&t, &duties);
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
        let (check, problems) = run(&t, &duties);
        assert!(problems.is_empty(), "{problems}");
        assert_eq!((check.fresh, check.mismatches), (40, 0));
        // The host wanted pulses there: every frame of the gap is named.
        let mut wanted = duties.clone();
        wanted[25] = 4800;
        let (_, problems) = run(&t, &wanted);
        assert!(problems.contains("frame 25: wrote 0 counts"), "{problems}");
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
        let [early, whole] = [5.0, 20.0].map(|rise| Measured { rise, width: 10.0 });
        assert_eq!(measure(&train), vec![whole]);
        assert_eq!(spans(&train, 0.0), vec![early, whole]);
        assert!(measure(&Train::default()).is_empty());
    }

    #[test]
    fn frames_stopping_before_a_reset_hold_the_last_duty() {
        let duties = ramp(30);
        let mut t = train(&duties, 36.0 * 20e6);
        let period = TIMING.period_ns();
        for n in 30..35 {
            let rise = (f64::from(n) + 0.5) * period + 10.0;
            let fall = rise + f64::from(duties[29]) * TIMING.count_ns;
            t.edges.extend([(rise, true), (fall, false)]);
        }
        t.edges.push((35.5 * period + 10.0, true)); // cut by the reset
        let (check, problems) = run(&t, &duties);
        assert!(problems.is_empty(), "{problems}");
        assert_eq!((check.fresh, check.held), (30, 5));
    }
}
