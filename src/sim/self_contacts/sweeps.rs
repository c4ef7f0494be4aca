//! The pushes' sweeps: Gauss–Seidel over the pairs found, each pair closer than the
//! thickness pushed apart in turn. The first sweep leaves out of the others every pair
//! whose sides are `within` apart or more when it comes to them (one that far comes into
//! contact within the sweeps only where pushes elsewhere move its particles that much; the
//! next substep pushes it then, and the continuous check, not the pushes, keeps the
//! guarantee). A pair found apart is tested again in a later sweep only where the pushes
//! since could have closed what it had over the thickness: each push adds how far it
//! moved each of its particles to that particle's running sum, and a side comes no nearer
//! than its farthest-moved particle has gone since (a point of a side is its particles'
//! weighted mean). Where cloths lie stacked (`layers`), most pairs stay apart through the
//! sweeps, and each test would find the closest points of two sides again.

use glam::Vec3;

use super::found::Found;
use super::primitives::{Pair, push_apart};
use super::search::{Owners, pairs};
use crate::cloth::{ClothModel, ClothState};

/// What the sweeps keep between pairs: scratch, reused every pass.
#[derive(Clone, Debug, Default)]
pub(super) struct Sweeps {
    /// Each particle's running sum of how far the pushes of this pass moved it, m.
    moved: Vec<f32>,
    /// The pairs the first sweep did not leave out, each with its least distance over the
    /// thickness when last found apart, m (negative: test it), and its four particles'
    /// sums then.
    near: Vec<(Pair, f32, [f32; 4])>,
    /// The particles the pushes of this pass moved, each once, and whether each is among
    /// them.
    pushed: Vec<u32>,
    is_pushed: Vec<bool>,
}

/// A pair's slack is kept short of what its test measured by this share of it: the
/// distances are rounded, and a pair passed by must be one its test would leave.
const ROUNDING: f32 = 1e-4;

impl Sweeps {
    /// Sweeps `count` times through the pairs `found`, pushing each closer than
    /// `thickness` apart with `friction` (see [`push_apart`]; `start`: the substep's, which
    /// tells the side; `held`: the particles resting on a solid), the first sweep leaving
    /// out of the others those `within` apart or more. Returns the pushes.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn push(
        &mut self,
        count: usize,
        (found, owners): (&Found, &Owners),
        [thickness, friction, within]: [f32; 3],
        model: &ClothModel,
        start: &[Vec3],
        state: &mut ClothState,
        held: &[bool],
    ) -> usize {
        self.moved.clear();
        self.moved.resize(state.pos.len(), 0.0);
        self.near.clear();
        for &i in &self.pushed {
            self.is_pushed[i as usize] = false;
        }
        self.pushed.clear();
        self.is_pushed.resize(state.pos.len(), false);
        let (pushed, is_pushed) = (&mut self.pushed, &mut self.is_pushed);
        let mut pushes = 0;
        let mut push = |moved: &mut [f32], pair: &Pair, reach: f32| {
            let ids = pair.ids();
            let before = ids.map(|i| state.pos[i]);
            let outcome = push_apart(
                pair,
                [thickness, friction, reach],
                model,
                start,
                state,
                held,
            );
            if outcome == Ok(true) {
                pushes += 1;
                for (j, &i) in ids.iter().enumerate() {
                    moved[i] += state.pos[i].distance(before[j]);
                    if !std::mem::replace(&mut is_pushed[i], true) {
                        pushed.push(i as u32);
                    }
                }
            }
            outcome
        };
        // A pair's slack after a push's `outcome`: how far apart over the thickness it
        // was found, and its particles' sums then; none where it was within it.
        let slack_after = |outcome: Result<bool, f32>, ids: [usize; 4], moved: &[f32]| match outcome
        {
            Err(apart) => (
                (apart - thickness) - ROUNDING * apart,
                ids.map(|i| moved[i]),
            ),
            Ok(_) => (-1.0, [0.0; 4]),
        };
        // The first sweep measures out to `within`; the others, to the thickness, go
        // through only the pairs it found nearer.
        for pair in pairs(found, &model.triangles, owners) {
            let outcome = push(&mut self.moved, &pair, within);
            if !matches!(outcome, Err(apart) if apart >= within) {
                let (slack, since) = slack_after(outcome, pair.ids(), &self.moved);
                self.near.push((pair, slack, since));
            }
        }
        for _ in 1..count {
            for (pair, slack, since) in &mut self.near {
                let (ids, k, moved) = (pair.ids(), pair.first_side(), &self.moved);
                let drift = |r: std::ops::Range<usize>| {
                    r.map(|j| moved[ids[j]] - since[j]).fold(0.0f32, f32::max)
                };
                if *slack > drift(0..k) + drift(k..4) {
                    continue;
                }
                let outcome = push(&mut self.moved, pair, thickness);
                (*slack, *since) = slack_after(outcome, ids, &self.moved);
            }
        }
        pushes
    }

    /// The particles the last pass's pushes moved, each once (the others are where it
    /// found them).
    pub(super) fn pushed(&self) -> &[u32] {
        &self.pushed
    }
}
