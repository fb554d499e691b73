//! The gesture layers: one starts over those playing, which fade out
//! under it, and each frame sums them per axis with the idle's duck.

use crate::command::GestureRequest;

use super::super::error::BehaviourError;
use super::super::fixed::{ONE, mul, smootherstep};
use super::super::gesture::{self, GesturePlan};
use super::super::params::BehaviourParams;
use super::Mixer;
use super::math::Sums;

/// A gesture layer: its plan, start, and the start of its fade-out
/// (times in µs on the frame path's clock).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Layer {
    plan: GesturePlan,
    start: u32,
    release: Option<u32>,
    /// µs from `start` to the layer's end: its plan's, or its fade's once
    /// released.
    stop: u32,
}

impl Layer {
    /// The time the layer ends at (its plan's end, or its fade's).
    #[inline]
    pub(super) const fn end(&self) -> u32 {
        self.start.wrapping_add(self.stop)
    }
}

impl Mixer {
    /// Starts a gesture layer for `request` (the others fade under it),
    /// or says when a layer frees if every one plays.
    pub(super) fn gesture(
        &mut self,
        request: &GestureRequest,
    ) -> Result<GesturePlan, BehaviourError> {
        let plan = gesture::plan(&self.params, request)?;
        let next = self.next;
        let Some(free) = self.layers.iter().position(Option::is_none) else {
            // Every layer plays: the one that ends first frees first.
            let left = self
                .layers
                .iter()
                .flatten()
                .map(|l| l.end().wrapping_sub(next).min(l.stop))
                .min()
                .unwrap_or(0);
            // The layer is cleared while mixing the first frame at or
            // past its end.
            return Err(BehaviourError::Busy {
                retry_in: BehaviourParams::millis(left.saturating_add(self.period)),
            });
        };
        let blend = self.params.blend.len();
        // The new layer starts, and the others fade, from the last frame
        // mixed (see `apply_at`).
        let start = self.now;
        for layer in self.layers.iter_mut().flatten() {
            if layer.release.is_none() {
                layer.release = Some(start);
                // The fade ends `blend` on, if the plan has not ended by then.
                let fade_end = start.wrapping_sub(layer.start).saturating_add(blend);
                layer.stop = layer.stop.min(fade_end);
            }
        }
        if let Some(slot) = self.layers.get_mut(free) {
            *slot = Some(Layer {
                plan,
                start,
                release: None,
                stop: plan.span.len(),
            });
        }
        Ok(plan)
    }

    /// The gesture layers at time `now`, summed per axis; clears the
    /// layers that have ended.
    #[inline]
    pub(super) fn layers(&mut self, now: u32) -> Sums {
        let mut sums = Sums::NONE;
        let params = &self.params;
        for slot in &mut self.layers {
            let Some(layer) = slot else { continue };
            let t = now.wrapping_sub(layer.start);
            if t >= layer.stop {
                *slot = None;
                continue;
            }
            // t < stop ≤ the plan's span.
            let (mut value, mut strength) = layer.plan.at(t);
            if let Some(release) = layer.release {
                // now − release < blend: before the stop.
                let fade = ONE - smootherstep(params.blend.progress(now.wrapping_sub(release)));
                value = mul(value, fade);
                strength = mul(strength as i32, fade) as u32;
            }
            let i = layer.plan.kind.axis().index();
            if let (Some(a), Some(d)) = (sums.add.get_mut(i), sums.duck.get_mut(i)) {
                *a += value;
                // (`mul` by 1 is exact: the factors of 1 are skipped.)
                let lowered = if strength == ONE {
                    params.duck
                } else {
                    mul(params.duck as i32, strength) as u32
                };
                *d = if *d == ONE {
                    ONE - lowered
                } else {
                    mul(*d as i32, ONE - lowered) as u32
                };
                sums.active |= 1 << i;
            }
        }
        sums
    }
}
