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
use super::primitives::push_apart;
use super::search::{Owners, pairs};
use crate::cloth::{ClothModel, ClothState};

/// What the sweeps keep between pairs: scratch, reused every pass.
#[derive(Clone, Debug, Default)]
pub(super) struct Sweeps {
    /// Each particle's running sum of how far the pushes of this pass moved it, m.
    moved: Vec<f32>,
    /// Each pair's (in the list's order) least distance over the thickness when last
    /// found apart, m (negative: test it; `+∞`: left out), and its four particles' sums
    /// then.
    slack: Vec<f32>,
    since: Vec<[f32; 4]>,
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
        self.slack.clear();
        self.slack.resize(found.len(), -1.0);
        self.since.resize(found.len(), [0.0; 4]);
        let mut pushes = 0;
        for sweep in 0..count {
            // The first sweep measures out to `within`, the others to the thickness.
            let reach = if sweep == 0 { within } else { thickness };
            let listed = pairs(found, &model.triangles, owners);
            for ((pair, slack), since) in listed.zip(&mut self.slack).zip(&mut self.since) {
                let ids = pair.ids();
                let k = pair.first_side();
                let moved = &self.moved;
                let drift = |r: std::ops::Range<usize>| {
                    r.map(|j| moved[ids[j]] - since[j]).fold(0.0f32, f32::max)
                };
                if *slack > drift(0..k) + drift(k..4) {
                    continue;
                }
                let before = ids.map(|i| state.pos[i]);
                let pair_at = [thickness, friction, reach];
                match push_apart(&pair, pair_at, model, start, state, held) {
                    Err(apart) if sweep == 0 && apart >= within => *slack = f32::INFINITY,
                    Err(apart) => {
                        *slack = (apart - thickness) - ROUNDING * apart;
                        *since = ids.map(|i| self.moved[i]);
                    }
                    Ok(pushed) => {
                        *slack = -1.0;
                        if pushed {
                            pushes += 1;
                            for (j, &i) in ids.iter().enumerate() {
                                self.moved[i] += state.pos[i].distance(before[j]);
                            }
                        }
                    }
                }
            }
        }
        pushes
    }
}
