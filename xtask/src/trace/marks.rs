//! What the script's commands did, as marks for the summary and the plot
//! (a look's planned return to the centre included); and the plot.

use idle_head_core::behaviour::{Applied, BehaviourError, BehaviourParams};
use idle_head_core::command::{Action, Hold, LookRequest};
use idle_head_core::console::{PORT_REPLY, Reply, outcome_reply};
use idle_head_core::{Angle, Axis, Millis};

use super::Trace;
use crate::plot::{self, GREY, RED};
use plotters::style::RGBColor;

/// What kind of motion a mark stands for (`Other`: a rest or a wake, idle,
/// stop, a refused command).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Gesture,
    Gaze,
    Return,
    Other,
}

/// A command as applied, or a look's return: when (ms), how long its motion
/// lasts (ms, 0: a switch), on which axes, a short label (`nod`, `look
/// (clamped)`, `return`, ...) and the console's reply (for a return: what
/// it is).
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    pub t_ms: u64,
    pub span_ms: u64,
    pub axes: Vec<Axis>,
    pub kind: Kind,
    pub label: String,
    pub reply: String,
}

impl Mark {
    pub fn refused(&self) -> bool {
        self.reply.starts_with("err")
    }
}

/// The marks of the command `text` (script line `line`, 0 for another
/// source), applied at `t_ms` with `outcome`: its own, and for a look that
/// returns, the return.
pub fn marks(
    text: &str,
    line: usize,
    t_ms: u64,
    outcome: &Result<Applied, BehaviourError>,
    params: &BehaviourParams,
) -> Vec<Mark> {
    let word = text.split_whitespace().next().unwrap_or("");
    let gaze = vec![Axis::Pitch, Axis::Yaw];
    let (axes, span, kind) = match outcome {
        Ok(Applied::Gesture(plan)) => (vec![plan.kind.axis()], plan.duration, Kind::Gesture),
        Ok(Applied::Look(look)) => (gaze.clone(), look.duration, Kind::Gaze),
        Ok(Applied::Center(ms)) => (gaze.clone(), *ms, Kind::Gaze),
        Ok(Applied::Rest(ms) | Applied::Wake(ms)) => (Axis::ALL.to_vec(), *ms, Kind::Other),
        _ => (vec![], Millis(0), Kind::Other),
    };
    let label = match outcome {
        Err(_) => format!("{word} (refused)"),
        Ok(Applied::Look(look)) if look.clamped => "look (clamped)".to_owned(),
        Ok(Applied::Idle(_)) => text.to_owned(),
        _ => word.to_owned(),
    };
    let mut out = [0; PORT_REPLY];
    let mut reply = Reply::new(&mut out);
    outcome_reply(&mut reply, outcome);
    let reply = String::from_utf8_lossy(reply.finish())
        .trim_end()
        .to_owned();
    let span_ms = u64::from(span.0);
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
        // As the gaze plans it: the move, the hold, the move back at the
        // rule's duration.
        let reply = format!(
            "(the look at line {line} returns to the centre after its {} ms hold, in {} ms)",
            hold.0, back.0
        );
        marks.push(Mark {
            t_ms: t_ms + span_ms + u64::from(hold.0),
            span_ms: u64::from(back.0),
            axes: gaze,
            kind: Kind::Return,
            label: "return".to_owned(),
            reply,
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
    let gesture = |i: &usize| marks[*i].kind == Kind::Gesture && !marks[*i].refused();
    let gaze = |m: &&Mark| m.kind == Kind::Gaze && !m.refused();
    let gestures: Vec<usize> = (0..marks.len()).filter(gesture).collect();
    for pair in gestures.windows(2) {
        let end = marks[pair[1]].t_ms + u64::from(blend_ms);
        let mark = &mut marks[pair[0]];
        mark.span_ms = mark.span_ms.min(end.saturating_sub(mark.t_ms));
    }
    // A return follows its look in the list; the next gaze move after the
    // look is the one that cancels or cuts it.
    let mut keep = vec![true; marks.len()];
    for i in 0..marks.len() {
        if marks[i].kind != Kind::Return {
            continue;
        }
        let next_move = marks[i + 1..].iter().find(gaze).map(|m| m.t_ms);
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
/// past five of them), each command marked and its motion shaded.
#[allow(clippy::cast_precision_loss)] // frame times, far below 2^52
pub fn draw(trace: &Trace, seed: Option<u32>, path: &std::path::Path) -> anyhow::Result<()> {
    let end_ms = trace.rows.last().map_or(0, |r| r.t_us / 1000);
    let (unit, ms_per_unit) = if end_ms > 300_000 {
        ("min", 60_000.0)
    } else {
        ("s", 1000.0)
    };
    let at = |ms: u64| ms as f64 / ms_per_unit;
    // A look's return in blue, a refused command's line in red.
    let (blue, light_blue) = (RGBColor(70, 110, 160), RGBColor(214, 230, 245));
    let orange = RGBColor(255, 228, 196);
    let marks: Vec<plot::Mark> = (trace.marks.iter())
        .map(|m| {
            let back = m.kind == Kind::Return;
            let line = match (m.refused(), back) {
                (true, _) => RED,
                (false, true) => blue,
                (false, false) => GREY,
            };
            plot::Mark {
                from: at(m.t_ms),
                to: at(m.t_ms + m.span_ms),
                axes: m.axes.clone(),
                label: m.label.clone(),
                line,
                shade: if back { light_blue } else { orange },
            }
        })
        .collect();
    let rows: Vec<(f64, [f64; 3])> = (trace.rows.iter())
        .map(|r| (at(r.t_us / 1000), r.angles.map(|a| f64::from(a) / 1000.0)))
        .collect();
    let loops = seed.map(|s| format!("loops of seed {s}"));
    let loops = loops.unwrap_or_else(|| "Table 2 loops".to_owned());
    let frames = rows.len();
    let title =
        format!("Commanded angles, {frames} frames ({loops}; after fade, limits and clamps)");
    let note = "shaded: a command's motion on the axes it moves (blue: a look's return to the \
                centre); dashed: when it was applied (red: refused)";
    let x = format!("time ({unit})");
    plot::motion(path, title, vec![note.to_owned()], &x, &rows, &marks)
}
