//! What the searches cost, counted in work rather than timed (so that the choice it makes
//! is the same on every run and every thread count): when a refresh of the triangles whose
//! particles left their boxes costs more than searching the whole tree again.

/// A triangle a refresh searches again, in the units of a whole search's triangle: each
/// is looked for from the tree's root on its own, where a whole search walks the tree
/// against itself once (`crumple` at 64²: about 1.0 µs a triangle refreshed, 0.08 µs a
/// triangle of a whole search, 0.08–0.25 µs a pair of triangles tested by either).
const REFRESHED_TRIANGLE: u64 = 12;

/// The pairs are judged by the boxes where the fast particles' refreshes, this many times
/// over, cost less than a whole search at the least: a whole search by the motion holds
/// for at most two substeps ([`super::window::LONGEST_WINDOW`]), and the boxes' room keeps
/// more pairs to push and check.
const FAST_SHARE: u64 = 4;

/// Whether refreshing the triangles of `fast` particles every substep, [`FAST_SHARE`]
/// times over, costs less than the least a whole search of a cloth of `triangles` and
/// `particles` costs (each triangle once; its pairs tested come on top). Counted from the
/// cloth alone, not from the searches before (whose count of pairs tested was tried: see
/// docs/performance.md), so that a frame redone from its start (the stability guard's)
/// decides as the frame did.
pub(super) fn few_refreshed_cheaper(fast: usize, triangles: usize, particles: usize) -> bool {
    let around = (3 * triangles).div_ceil(particles.max(1)) as u64;
    let each = REFRESHED_TRIANGLE * around * FAST_SHARE;
    each.saturating_mul(fast as u64) < triangles as u64
}

/// The work of the searches since the last whole search.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct SearchCosts {
    /// The last whole search's: its triangles and the pairs of triangles it tested.
    whole: u64,
    /// The refreshes' since, in the same units.
    spent: u64,
}

impl SearchCosts {
    /// A whole search of `triangles` that tested `tested` pairs of triangles.
    pub(super) fn searched(&mut self, triangles: usize, tested: u64) {
        self.whole = triangles as u64 + tested;
        self.spent = 0;
    }

    /// A refresh of `triangles` that tested `tested` pairs of triangles.
    pub(super) fn refreshed(&mut self, triangles: usize, tested: u64) {
        self.spent += REFRESHED_TRIANGLE * triangles as u64 + tested;
    }

    /// Whether the next search should be of the whole tree: the refreshes since the last
    /// one have cost as much as it did. A whole search gives every particle a new box,
    /// with room along its motion now; a refresh, only those that left theirs, so where a
    /// cloth keeps moving a few more leave every substep, and the refreshes would go on
    /// costing more than the searches they save. (Asked only where the pairs are judged
    /// by the boxes: by the motion, the window brings a whole search every few substeps.)
    pub(super) fn whole_due(&self) -> bool {
        self.whole > 0 && self.spent >= self.whole
    }
}
