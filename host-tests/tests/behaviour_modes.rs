//! The mixer's limit modes against the rule they follow, counted frame by
//! frame: an axis is in gesture mode while a gesture plays on it or a gaze
//! move moves it, and for `settle` after (counted down by the time passed,
//! late frames included). The mixer works the modes out only at
//! events (a layer or a move ends, an action is applied, a return is due, a
//! settle time runs out); this checks that it gives the modes of every frame
//! exactly, for random scripts of gestures, looks (held, or returning after
//! a hold) and moves back to the centre, with frames skipped.

use idle_head_core::Angle;
use idle_head_core::behaviour::{Applied, BehaviourParams, LimitMode, Mixer};
use idle_head_core::command::{Action, GestureKind, Hold};
use idle_head_core::units::Millis;
use proptest::prelude::*;

use host_tests::behaviour::{default_params as params, frame as time_of, gesture, look};

/// Frame period of the default configuration, µs.
const FRAME_US: u64 = 20_000;

/// A gesture layer as the rule sees it: its axis and end time (µs).
#[derive(Clone, Copy, Debug)]
struct Layer {
    axis: usize,
    end: u64,
    released: bool,
}

/// The modes counted frame by frame from what the actions answered, all
/// times in µs.
struct Model {
    layers: Vec<Layer>,
    /// The gaze move: start and end (moving in `start..end`).
    gaze: (u64, u64),
    /// The planned return: its start and end.
    back: Option<(u64, u64)>,
    params: BehaviourParams,
    left: [u64; 3],
    blend: u64,
    settle: u64,
    /// The last frame played, if any.
    last: Option<u64>,
}

/// `ms` in µs.
fn us(ms: Millis) -> u64 {
    u64::from(ms.0) * 1000
}

impl Model {
    /// An action applied before the next frame, as answered: it starts at
    /// the last frame played (0 before the first), so that the next frame is
    /// a step in.
    fn apply(&mut self, outcome: &Applied) {
        let start = self.last.unwrap_or(0);
        match outcome {
            Applied::Gesture(plan) => {
                for layer in &mut self.layers {
                    if !layer.released {
                        layer.released = true;
                        layer.end = layer.end.min(start + self.blend);
                    }
                }
                self.layers.push(Layer {
                    axis: plan.kind.axis().index(),
                    end: start + us(plan.duration),
                    released: false,
                });
            }
            Applied::Look(look) => {
                let end = start + us(look.duration);
                self.gaze = (start, end);
                self.back = match look.hold {
                    Hold::Stay => None,
                    Hold::Return(ms) => {
                        // Back along the rule's duration for the distance
                        // (within the gesture limits for these targets).
                        let pose = self.params.neutral_pose();
                        let far = (look.pitch.millidegrees() - pose[0].millidegrees())
                            .unsigned_abs()
                            .max((look.yaw.millidegrees() - pose[2].millidegrees()).unsigned_abs());
                        let gaze = self.params.config().gaze;
                        let back_ms = gaze.base.0 + (gaze.per_degree.0 * far).div_ceil(1000);
                        let next = end + us(ms).max(1);
                        Some((next, next + us(Millis(back_ms))))
                    }
                };
            }
            Applied::Center(ms) => {
                self.gaze = (start, start + us(*ms));
                self.back = None;
            }
            Applied::Idle(_) | Applied::Stop => {}
            // The rest has its own tests (`behaviour_rest`): this model
            // plays no rest.
            Applied::Rest(_) | Applied::Wake(_) => panic!("the model plays no rest: {outcome:?}"),
        }
    }

    /// The modes after the frame at `frame` (µs) is played (for the next
    /// frame).
    fn frame(&mut self, frame: u64) -> [LimitMode; 3] {
        let elapsed = self.last.map_or(1, |last| (frame - last).max(1));
        self.last = Some(frame);
        self.layers.retain(|l| frame < l.end);
        let mut on = [false; 3];
        for layer in &self.layers {
            on[layer.axis] = true;
        }
        if let Some(back) = self.back
            && frame >= back.0
        {
            self.gaze = back;
            self.back = None;
        }
        let moving = (self.gaze.0..self.gaze.1).contains(&frame);
        on[0] |= moving;
        on[2] |= moving;
        // The return starts next frame: pitch and yaw in gesture mode now.
        let soon = self.back.is_some_and(|back| frame + FRAME_US >= back.0);
        core::array::from_fn(|i| {
            self.left[i] = if on[i] {
                self.settle
            } else {
                self.left[i].saturating_sub(elapsed)
            };
            if on[i] || self.left[i] > 0 || (soon && i != 1) {
                LimitMode::Gesture
            } else {
                LimitMode::Idle
            }
        })
    }
}

/// One step of a script: frames to the next frame played (1: the next,
/// more: late frames skipped) and what to apply before it.
#[derive(Clone, Debug)]
struct Step {
    gap: u64,
    action: Option<Action>,
}

fn action() -> impl Strategy<Value = Action> {
    let kind = proptest::sample::select(GestureKind::ALL.to_vec());
    prop_oneof![
        (kind, proptest::option::of(1_u8..=3)).prop_map(|(kind, cycles)| {
            let cycles = if kind.row().max_cycles == 1 {
                None
            } else {
                cycles
            };
            gesture(kind, None, None, cycles)
        }),
        (
            -8000_i32..8000,
            -15_000_i32..15_000,
            proptest::option::of(300_u32..1500),
            prop_oneof![
                Just(Hold::Stay),
                (0_u32..2000).prop_map(|ms| Hold::Return(Millis(ms)))
            ],
        )
            .prop_map(|(pitch, yaw, ms, hold)| look(
                pitch,
                yaw,
                ms.map(Millis),
                Some(hold)
            )),
        proptest::option::of(300_u32..1500).prop_map(|ms| Action::Center {
            duration: ms.map(Millis)
        }),
    ]
}

fn step() -> impl Strategy<Value = Step> {
    (
        prop_oneof![8 => Just(1_u64), 1 => 2_u64..6, 1 => 10_u64..40],
        proptest::option::weighted(0.06, action()),
    )
        .prop_map(|(gap, action)| Step { gap, action })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(host_tests::cases(128)))]

    #[test]
    fn the_modes_are_those_of_the_frame_by_frame_count(
        script in proptest::collection::vec(step(), 100..600),
    ) {
        let params = params();
        let config = params.config();
        let mut model = Model {
            layers: Vec::new(),
            gaze: (0, 0),
            back: None,
            params,
            left: [0; 3],
            blend: us(config.blend),
            settle: us(config.settle),
            last: None,
        };
        let mut mixer = Mixer::new(params);
        let mut frame = 0;
        for (k, step) in script.iter().enumerate() {
            if let Some(action) = &step.action
                && let Ok(applied) = mixer.apply(action)
            {
                model.apply(&applied);
                // From the next frame on, as the driver gets them.
                let wanted = mixer.modes();
                if let Applied::Gesture(plan) = applied {
                    prop_assert_eq!(wanted[plan.kind.axis().index()], LimitMode::Gesture);
                }
            }
            mixer.frame(time_of(frame), [Angle::ZERO; 3]);
            let expected = model.frame(frame * FRAME_US);
            prop_assert_eq!(mixer.modes(), expected, "step {} at frame {}", k, frame);
            frame += step.gap;
        }
    }
}
