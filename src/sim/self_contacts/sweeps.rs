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
//!
//! From [`GROUPED_FROM`] pairs on, the sweeps go through the pairs in groups the team
//! shares: the particles are cut into [`SLABS`] slabs of equal count along the axis the
//! cloth spans farthest, and each pair goes to the smallest aligned run of slabs (one, two,
//! four or all eight) that holds its four particles. The groups of one size reach disjoint
//! particles, so the team pushes them side by side, size after size, each group's pairs in
//! the order found; the order does not depend on the team, and nor does the end state.
//! Fewer pairs are swept in the order found, on the caller.

use glam::Vec3;

use super::found::Found;
use super::primitives::{Pair, Particles, push_apart};
use super::search::{Owners, pairs};
use crate::cloth::{ClothModel, ClothState};
use crate::parallel::{Disjoint, Team};

/// Pairs from which the sweeps go through them in slabs' groups, shared with the team.
/// `layers` finds 20 000–100 000 a substep where its cloths lie pressed together;
/// `crumple` at 64², a hundred or so.
const GROUPED_FROM: usize = 4_096;

/// Slabs the particles are cut into for the groups (a power of two: each size of group is
/// twice the one before).
const SLABS: usize = 8;

/// Sizes of group: runs of one, two, four and eight slabs.
const LEVELS: usize = SLABS.trailing_zeros() as usize + 1;

/// A pair's slack is kept short of what its test measured by this share of it: the
/// distances are rounded, and a pair passed by must be one its test would leave.
const ROUNDING: f32 = 1e-4;

/// A pair the first sweep did not leave out, with its least distance over the thickness
/// when last found apart, m (negative: test it), and its four particles' sums then.
type Near = (Pair, f32, [f32; 4]);

/// One group of pairs and what its sweeps keep.
#[derive(Clone, Debug, Default)]
struct Group {
    /// Its pairs, in the order found (grouped sweeps only).
    pairs: Vec<Pair>,
    /// The pairs its first sweep did not leave out.
    near: Vec<Near>,
    tally: Tally,
}

/// What a group's pushes did this pass.
#[derive(Clone, Debug, Default)]
struct Tally {
    /// The particles they moved, each once.
    pushed: Vec<u32>,
    pushes: usize,
}

/// What the sweeps keep between pairs: scratch, reused every pass.
#[derive(Clone, Debug, Default)]
pub(super) struct Sweeps {
    /// Each particle's running sum of how far the pushes of this pass moved it, m.
    moved: Vec<f32>,
    /// Whether the pushes of this pass moved each particle.
    is_pushed: Vec<bool>,
    /// The particles the pushes of this pass moved, each once.
    pushed: Vec<u32>,
    /// The groups: one for sweeps in the order found; else by size of run, then by run.
    groups: Vec<Group>,
    /// Each particle's slab, and the coordinates the slabs are cut by (scratch).
    slab: Vec<u8>,
    along: Vec<f32>,
}

/// The first group of runs of `2^level` slabs.
fn level_start(level: usize) -> usize {
    (0..level).map(|l| SLABS >> l).sum()
}

/// The cloth's particles as one group of pairs reaches them.
struct Reach<'a> {
    pos: Disjoint<'a, Vec3>,
    vel: Disjoint<'a, Vec3>,
    moved: Disjoint<'a, f32>,
    is_pushed: Disjoint<'a, bool>,
}

impl Particles for &Reach<'_> {
    #[inline(always)]
    fn pos(&self, i: usize) -> Vec3 {
        // SAFETY: (here and below) a group's pairs reach only its own particles, and no
        // other group of them is pushed at the same time ([`Reach`]'s users).
        unsafe { *self.pos.at(i) }
    }
    #[inline(always)]
    fn vel(&self, i: usize) -> Vec3 {
        unsafe { *self.vel.at(i) }
    }
    #[inline(always)]
    fn move_by(&mut self, i: usize, by: Vec3) {
        unsafe { *self.pos.at(i) += by }
    }
    #[inline(always)]
    fn speed_up(&mut self, i: usize, by: Vec3) {
        unsafe { *self.vel.at(i) += by }
    }
}

impl Reach<'_> {
    fn moved(&self, i: usize) -> f32 {
        unsafe { *self.moved.at(i) }
    }
}

/// What one sweep of a group needs besides its particles.
struct Sweep<'a> {
    /// The thickness, the friction and how near the first sweep keeps pairs.
    at: [f32; 3],
    model: &'a ClothModel,
    start: &'a [Vec3],
    held: &'a [bool],
}

impl Sweep<'_> {
    /// Pushes `pair` apart where its sides are closer than the thickness, measuring out
    /// to `reach`; where it pushed, adds how far each particle moved to its sum.
    fn push(
        &self,
        reach: &Reach,
        tally: &mut Tally,
        pair: &Pair,
        within: f32,
    ) -> Result<bool, f32> {
        let [thickness, friction, _] = self.at;
        let ids = pair.ids();
        let before = ids.map(|i| reach.pos(i));
        let mut particles = reach;
        let outcome = push_apart(
            pair,
            [thickness, friction, within],
            self.model,
            self.start,
            &mut particles,
            self.held,
        );
        if outcome == Ok(true) {
            tally.pushes += 1;
            for (j, &i) in ids.iter().enumerate() {
                // SAFETY: as for [`Reach`]'s positions.
                unsafe { *reach.moved.at(i) += reach.pos(i).distance(before[j]) };
                if !std::mem::replace(unsafe { reach.is_pushed.at(i) }, true) {
                    tally.pushed.push(i as u32);
                }
            }
        }
        outcome
    }

    /// A pair's slack after a push's `outcome`: how far apart over the thickness it was
    /// found, and its particles' sums then; none where it was within it.
    fn slack_after(
        &self,
        outcome: Result<bool, f32>,
        ids: [usize; 4],
        reach: &Reach,
    ) -> (f32, [f32; 4]) {
        let thickness = self.at[0];
        match outcome {
            Err(apart) => (
                (apart - thickness) - ROUNDING * apart,
                ids.map(|i| reach.moved(i)),
            ),
            Ok(_) => (-1.0, [0.0; 4]),
        }
    }

    /// The first sweep through `pairs`, out to the reach; keeps the nearer in `near`.
    fn first(
        &self,
        reach: &Reach,
        (near, tally): (&mut Vec<Near>, &mut Tally),
        pairs: impl Iterator<Item = Pair>,
    ) {
        let within = self.at[2];
        for pair in pairs {
            let outcome = self.push(reach, tally, &pair, within);
            if !matches!(outcome, Err(apart) if apart >= within) {
                let (slack, since) = self.slack_after(outcome, pair.ids(), reach);
                near.push((pair, slack, since));
            }
        }
    }

    /// A later sweep through the group's near pairs, out to the thickness, passing by
    /// those the pushes since they were measured cannot have closed.
    fn again(&self, reach: &Reach, (near, tally): (&mut Vec<Near>, &mut Tally)) {
        let thickness = self.at[0];
        for (pair, slack, since) in near.iter_mut() {
            let (ids, k) = (pair.ids(), pair.first_side());
            let drift = |r: std::ops::Range<usize>| {
                r.map(|j| reach.moved(ids[j]) - since[j])
                    .fold(0.0f32, f32::max)
            };
            if *slack > drift(0..k) + drift(k..4) {
                continue;
            }
            let outcome = self.push(reach, tally, pair, thickness);
            (*slack, *since) = self.slack_after(outcome, ids, reach);
        }
    }
}

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
        at: [f32; 3],
        model: &ClothModel,
        start: &[Vec3],
        state: &mut ClothState,
        held: &[bool],
    ) -> usize {
        let n = state.pos.len();
        self.moved.clear();
        self.moved.resize(n, 0.0);
        for &i in &self.pushed {
            self.is_pushed[i as usize] = false;
        }
        self.pushed.clear();
        self.is_pushed.resize(n, false);
        let grouped = found.len() >= GROUPED_FROM;
        let groups = if grouped { level_start(LEVELS) } else { 1 };
        self.groups.resize_with(level_start(LEVELS), Group::default);
        for group in &mut self.groups {
            group.near.clear();
            group.tally.pushed.clear();
            group.tally.pushes = 0;
        }
        if grouped {
            self.group(pairs(found, &model.triangles, owners), &state.pos);
        }
        let sweep = Sweep {
            at,
            model,
            start,
            held,
        };
        let reach = Reach {
            pos: Disjoint::new(&mut state.pos),
            vel: Disjoint::new(&mut state.vel),
            moved: Disjoint::new(&mut self.moved),
            is_pushed: Disjoint::new(&mut self.is_pushed),
        };
        if grouped {
            // The groups' reach: `group` put each pair in the run of slabs that holds its
            // particles, and the runs of one size are disjoint.
            let team = Team::current();
            let groups = Disjoint::new(&mut self.groups);
            for round in 0..count {
                for level in 0..LEVELS {
                    let first = level_start(level);
                    team.run_large_pieces(SLABS >> level, &|_, run| {
                        // SAFETY: each run is one piece, run once.
                        let group = unsafe { groups.at(first + run) };
                        let lists = (&mut group.near, &mut group.tally);
                        if round == 0 {
                            sweep.first(&reach, lists, group.pairs.iter().copied());
                        } else {
                            sweep.again(&reach, lists);
                        }
                    });
                }
            }
        } else {
            let group = &mut self.groups[0];
            let listed = pairs(found, &model.triangles, owners);
            sweep.first(&reach, (&mut group.near, &mut group.tally), listed);
            for _ in 1..count {
                sweep.again(&reach, (&mut group.near, &mut group.tally));
            }
        }
        let mut pushes = 0;
        for group in &self.groups[..groups] {
            pushes += group.tally.pushes;
            self.pushed.extend_from_slice(&group.tally.pushed);
        }
        pushes
    }

    /// The particles the last pass's pushes moved, each once (the others are where it
    /// found them).
    pub(super) fn pushed(&self) -> &[u32] {
        &self.pushed
    }

    /// The pairs `found` in the order the sweeps go through them with the particles at
    /// `pos`, and whether they go in groups.
    #[cfg(test)]
    pub(super) fn order(
        &mut self,
        (found, owners): (&Found, &Owners),
        model: &ClothModel,
        pos: &[Vec3],
    ) -> (Vec<Pair>, bool) {
        let listed = pairs(found, &model.triangles, owners);
        if found.len() < GROUPED_FROM {
            return (listed.collect(), false);
        }
        self.groups.resize_with(level_start(LEVELS), Group::default);
        self.group(listed, pos);
        let order = self.groups.iter().flat_map(|g| g.pairs.iter().copied());
        (order.collect(), true)
    }

    /// Cuts the particles at `pos` into slabs and puts each of `pairs` in its group.
    fn group(&mut self, pairs: impl Iterator<Item = Pair>, pos: &[Vec3]) {
        let (lo, hi) = (pos.iter()).fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
        let axis = (hi - lo).max_position();
        let n = pos.len();
        self.along.clear();
        self.along.extend(pos.iter().map(|p| p[axis]));
        // The slabs' bounds: the coordinates at every SLABS-th share of the particles,
        // each picked from what lies above the one before.
        let (mut cuts, mut below) = ([f32::INFINITY; SLABS - 1], 0);
        for (k, cut) in cuts.iter_mut().enumerate() {
            let at = (k + 1) * n / SLABS;
            if at < n {
                let above = &mut self.along[below..];
                *cut = *above.select_nth_unstable_by(at - below, f32::total_cmp).1;
                below = at;
            }
        }
        self.slab.clear();
        (self.slab).extend(
            pos.iter()
                .map(|p| cuts.partition_point(|&c| c <= p[axis]) as u8),
        );
        for group in &mut self.groups {
            group.pairs.clear();
        }
        for pair in pairs {
            let slabs = pair.ids().map(|i| self.slab[i]);
            let (lo, hi) = (slabs.iter().min(), slabs.iter().max());
            let (lo, hi) = (*lo.unwrap_or(&0) as usize, *hi.unwrap_or(&0) as usize);
            // The smallest aligned run of slabs that holds both.
            let level = (usize::BITS - (lo ^ hi).leading_zeros()) as usize;
            self.groups[level_start(level) + (lo >> level)]
                .pairs
                .push(pair);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pair goes to the one run of slabs that holds its four particles and whose
    /// halves do not (so the runs of one size, pushed side by side, reach disjoint
    /// particles), and the slabs hold equal shares of the particles, in order along the
    /// cloud's longest axis: random pairs, most of them local, over a cloud of particles
    /// stretched along z, some of which share their z.
    #[test]
    fn each_pair_goes_to_the_least_run_of_slabs_that_holds_it() {
        let mut rnd = crate::test_rng::uniform(7);
        let n = 1003;
        // z crowded towards 0 (slabs of equal width would hold unequal shares), on a 1 mm
        // grid, so that some particles share it (up to seven, near 0); in order of z.
        let mut pos: Vec<Vec3> = (0..n)
            .map(|_| {
                let z = rnd();
                Vec3::new(rnd(), rnd(), (z * z * 10_000.0).round() * 0.001)
            })
            .collect();
        pos.sort_by(|a, b| a.z.total_cmp(&b.z));
        // Pairs of particles near in z, as a cloth's are, and some far apart.
        let mut pairs = Vec::new();
        while pairs.len() < 20_000 {
            let first = (rnd() * n as f32) as usize % n;
            let spread = if pairs.len() % 10 == 0 { n } else { 60 };
            let ids: [u32; 4] =
                std::array::from_fn(|_| ((first + (rnd() * spread as f32) as usize) % n) as u32);
            let [a, b, c, d] = ids;
            if (1..4).any(|j| ids[..j].contains(&ids[j])) {
                continue;
            }
            pairs.push(if pairs.len() % 2 == 0 {
                Pair::vertex_triangle(a, [b, c, d])
            } else {
                Pair::edge_edge([a, b], [c, d])
            });
        }
        let mut sweeps = Sweeps::default();
        sweeps
            .groups
            .resize_with(level_start(LEVELS), Group::default);
        sweeps.group(pairs.iter().copied(), &pos);
        // The slabs: equal counts, in order along z.
        let mut counts = [0usize; SLABS];
        for &s in &sweeps.slab {
            counts[s as usize] += 1;
        }
        assert!(
            counts.iter().all(|&c| c.abs_diff(n / SLABS) <= 8),
            "{counts:?}"
        );
        for i in 0..n {
            for j in 0..n {
                if sweeps.slab[i] < sweeps.slab[j] {
                    assert!(pos[i].z < pos[j].z);
                }
            }
        }
        let mut seen = 0;
        let mut by_level = [0usize; LEVELS];
        for (level, count) in by_level.iter_mut().enumerate() {
            for run in 0..SLABS >> level {
                for pair in &sweeps.groups[level_start(level) + run].pairs {
                    let slabs = pair.ids().map(|i| sweeps.slab[i] as usize);
                    let span = (run << level)..((run + 1) << level);
                    assert!(
                        slabs.iter().all(|s| span.contains(s)),
                        "{slabs:?} in {span:?}"
                    );
                    if level > 0 {
                        let half = span.start + (1 << (level - 1));
                        assert!(
                            slabs.iter().any(|&s| s < half) && slabs.iter().any(|&s| s >= half)
                        );
                    }
                    seen += 1;
                    *count += 1;
                }
            }
        }
        assert_eq!(seen, pairs.len());
        // Random pairs span the cloud: every size of run has pairs of its own.
        assert!(by_level.iter().all(|&c| c > 100), "{by_level:?}");
    }
}
