//! What the script's commands did, as marks for the summary and the plot:
//! when each was applied, how long its motion lasts and on which axes, and
//! the return to the centre a look plans after its hold; and the plot.

use idle_head_core::behaviour::{Applied, BehaviourError, BehaviourParams};
use idle_head_core::command::{Action, Hold, LookRequest};
use idle_head_core::{Angle, Axis, Millis};

use super::{Trace, script::Event};
use crate::plot::{self, GREY, RED};
use plotters::style::RGBColor;

/// What kind of motion a mark stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A gesture (any of the core's gesture table).
    Gesture,
    /// A move of the gaze: `look` or `center`.
    Gaze,
    /// A look's return to the centre after its hold.
    Return,
    /// A rest or a wake: the blend to the rest pose and back.
    Rest,
    /// Anything else (idle, stop, a refused command).
    Other,
}

/// A command as applied, or a look's return.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// When it was applied (or the return starts), in ms.
    pub t_ms: u64,
    /// How long its motion lasts, in ms (0: a switch).
    pub span_ms: u64,
    pub axes: Vec<Axis>,
    pub kind: Kind,
    /// A short label (`nod`, `look clamped`, `return`, ...).
    pub label: String,
    /// The reply a console would give (for a return: what it is).
    pub reply: String,
}

impl Mark {
    /// Whether the head refused it.
    pub fn refused(&self) -> bool {
        self.reply.starts_with("err")
    }
}

/// The marks of `event`, applied at `t_ms` with `outcome`: its own, and
/// for a look that returns, the return.
pub fn marks(
    event: &Event,
    t_ms: u64,
    outcome: &Result<Applied, BehaviourError>,
    params: &BehaviourParams,
) -> Vec<Mark> {
    let word = event
        .text
        .split_whitespace()
        .next()
        .unwrap_or("")
        .to_owned();
    let (axes, span_ms, kind, label, reply) = match outcome {
        Err(e) => (
            vec![],
            0,
            Kind::Other,
            format!("{word} (refused)"),
            format!("err {} {e}", e.code()),
        ),
        Ok(Applied::Gesture(plan)) => (
            vec![plan.kind.axis()],
            u64::from(plan.duration.0),
            Kind::Gesture,
            word,
            format!(
                "ok {} {} mdeg {} cycles {} ms intensity {}",
                plan.kind.name(),
                plan.amplitude.millidegrees(),
                plan.cycles,
                plan.duration.0,
                plan.intensity.get()
            ),
        ),
        Ok(Applied::Look(look)) => (
            vec![Axis::Pitch, Axis::Yaw],
            u64::from(look.duration.0),
            Kind::Gaze,
            if look.clamped {
                "look (clamped)".to_owned()
            } else {
                word
            },
            format!(
                "ok look{} {} {} {} ms",
                if look.clamped { " clamped" } else { "" },
                look.pitch.millidegrees(),
                look.yaw.millidegrees(),
                look.duration.0
            ),
        ),
        Ok(Applied::Center(ms)) => (
            vec![Axis::Pitch, Axis::Yaw],
            u64::from(ms.0),
            Kind::Gaze,
            word,
            format!("ok center {} ms", ms.0),
        ),
        Ok(Applied::Idle(p)) => (
            vec![],
            0,
            Kind::Other,
            event.text.clone(),
            format!("ok idle {} %", p.get()),
        ),
        Ok(Applied::Stop) => (vec![], 0, Kind::Other, word, "ok stop".to_owned()),
        Ok(Applied::Rest(ms) | Applied::Wake(ms)) => {
            let what = if matches!(outcome, Ok(Applied::Rest(_))) {
                "rest"
            } else {
                "wake"
            };
            let reply = format!("ok {what} {} ms", ms.0);
            (Axis::ALL.to_vec(), u64::from(ms.0), Kind::Rest, word, reply)
        }
    };
    let mut marks = vec![Mark {
        t_ms,
        span_ms,
        axes,
        kind,
        label,
        reply,
    }];
    if let Ok(Applied::Look(look)) = outcome
        && let Hold::Return(hold) = look.hold
        && let Some(back) = return_duration(params, look.pitch, look.yaw)
    {
        // As the gaze plans it: the move, then the hold, then the move
        // back at the rule's duration.
        marks.push(Mark {
            t_ms: t_ms + u64::from(look.duration.0) + u64::from(hold.0),
            span_ms: u64::from(back.0),
            axes: vec![Axis::Pitch, Axis::Yaw],
            kind: Kind::Return,
            label: "return".to_owned(),
            reply: format!(
                "(the look at line {} returns to the centre after its {} ms hold, in {} ms)",
                event.line, hold.0, back.0
            ),
        });
    }
    marks
}

/// How long the way back from a look at `pitch`, `yaw` takes: as long as
/// the way there from the centre at the rule's duration, which the core
/// answers for a look from a head at rest.
fn return_duration(params: &BehaviourParams, pitch: Angle, yaw: Angle) -> Option<Millis> {
    let there = Action::Look(LookRequest {
        pitch,
        yaw,
        duration: None,
        hold: Some(Hold::Stay),
    });
    match params.check(&there) {
        Ok(Applied::Look(look)) => Some(look.duration),
        _ => None,
    }
}

/// Settles the marks once the run is over: a gesture interrupted by a newer
/// one ends within `blend_ms` of it; a look's return does not happen when
/// another look or a `center` comes before it starts, and ends where one
/// comes while it plays; a return after `end_ms` is left out. The marks end
/// up in time order.
pub fn settle(marks: &mut Vec<Mark>, blend_ms: u32, end_ms: u64) {
    let applied = |m: &Mark| !m.refused();
    let gestures: Vec<usize> = (0..marks.len())
        .filter(|&i| marks[i].kind == Kind::Gesture && applied(&marks[i]))
        .collect();
    for pair in gestures.windows(2) {
        let next = marks[pair[1]].t_ms;
        let mark = &mut marks[pair[0]];
        let end = next + u64::from(blend_ms);
        if mark.t_ms + mark.span_ms > end {
            mark.span_ms = end - mark.t_ms;
        }
    }
    // A return follows its look in the list; the next gaze move after the
    // look is the one that cancels or cuts it.
    let mut keep = vec![true; marks.len()];
    for i in 0..marks.len() {
        if marks[i].kind != Kind::Return {
            continue;
        }
        let next_move = marks[i + 1..]
            .iter()
            .find(|m| m.kind == Kind::Gaze && applied(m))
            .map(|m| m.t_ms);
        let mark = &mut marks[i];
        match next_move {
            Some(t) if t <= mark.t_ms => keep[i] = false,
            Some(t) if t < mark.t_ms + mark.span_ms => mark.span_ms = t - mark.t_ms,
            _ => {}
        }
        if mark.t_ms >= end_ms {
            keep[i] = false;
        }
    }
    let mut keep = keep.into_iter();
    marks.retain(|_| keep.next().unwrap_or(true));
    marks.sort_by_key(|m| m.t_ms);
}

/// Draws `trace` to the PNG `path`: the three axes over time (in minutes
/// past five of them), each command marked where it was applied and its
/// motion shaded on the axes it moves (a look's return in blue, a refused
/// command in red).
#[allow(clippy::cast_precision_loss)] // frame times, far below 2^52
pub fn draw(trace: &Trace, seed: Option<u32>, path: &std::path::Path) -> anyhow::Result<()> {
    let end_ms = trace.rows.last().map_or(0, |r| r.t_ms);
    let (unit, ms_per_unit) = if end_ms > 300_000 {
        ("min", 60_000.0)
    } else {
        ("s", 1000.0)
    };
    let at = |ms: u64| ms as f64 / ms_per_unit;
    let back = |m: &Mark| m.kind == Kind::Return;
    let marks: Vec<plot::Mark> = (trace.marks.iter())
        .map(|m| plot::Mark {
            from: at(m.t_ms),
            to: at(m.t_ms + m.span_ms),
            axes: m.axes.clone(),
            label: m.label.clone(),
            line: if m.refused() {
                RED
            } else if back(m) {
                RGBColor(70, 110, 160)
            } else {
                GREY
            },
            shade: if back(m) {
                RGBColor(214, 230, 245)
            } else {
                RGBColor(255, 228, 196)
            },
        })
        .collect();
    let rows: Vec<(f64, [f64; 3])> = (trace.rows.iter())
        .map(|r| (at(r.t_ms), r.angles.map(|a| f64::from(a) / 1000.0)))
        .collect();
    let loops = seed.map_or_else(
        || "Table 2 loops".to_owned(),
        |s| format!("loops of seed {s}"),
    );
    let title = format!(
        "Commanded angles, {} frames ({loops}; after fade, limits and clamps)",
        rows.len()
    );
    let note = "shaded: a command's motion on the axes it moves (blue: a look's return to the \
                centre); dashed: when it was applied (red: refused)";
    plot::motion(
        path,
        title,
        vec![note.to_owned()],
        &format!("time ({unit})"),
        &rows,
        &marks,
    )
}
