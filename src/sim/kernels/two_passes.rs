//! The spring forces in two passes, for callers that share the passes out in their own team
//! sections: every block's sums first, then each particle's sum of the blocks.

use std::ops::Range;

use crate::parallel::Disjoint;

use super::components::Components;
use super::spring_runs::{BlockBuffers, Buffers, SpringRuns};
use crate::cloth::Real;

/// The spring forces in two passes ([`TwoPasses::of`]): first every block's sums
/// ([`TwoPasses::blocks`], shared out by blocks), then, per range of particles, their sum
/// ([`TwoPasses::add_to`]).
pub struct TwoPasses<'a, R: Real = f32> {
    runs: &'a SpringRuns<R>,
    bufs: std::sync::MutexGuard<'a, Buffers<R>>,
}

/// The first pass of [`TwoPasses`], which team members share by blocks.
pub struct BlockPass<'a, R: Real = f32> {
    runs: &'a SpringRuns<R>,
    blocks: Disjoint<'a, BlockBuffers<R>>,
}

impl<'a, R: Real> TwoPasses<'a, R> {
    /// The forces of `runs` in two passes, for a caller that runs them in its own team
    /// sections between other work (see [`ForceSet`](crate::sim::ForceSet)'s fused path):
    /// the buffers stay locked until the result is dropped. The same operations as
    /// [`SpringRuns::add_forces_components`], so the same bits.
    pub fn of(runs: &'a SpringRuns<R>) -> Self {
        let mut bufs = runs.scratch.lock();
        runs.size_buffers(&mut bufs.blocks);
        TwoPasses { runs, bufs }
    }

    /// Whether positions and velocities of `n` particles reach every spring's ends.
    pub fn fits(&self, n: usize) -> bool {
        n >= self.runs.particles
    }

    /// The first pass, for the members of a section to share.
    pub fn blocks(&mut self) -> BlockPass<'_, R> {
        BlockPass {
            runs: self.runs,
            blocks: Disjoint::new(&mut self.bufs.blocks[..]),
        }
    }

    /// Adds the forces on particles `range` to `f` (that range of the forces): each block's
    /// sums in block order, as [`SpringRuns::add_forces_components`] does. Particles past
    /// the springs' last one get nothing.
    pub fn add_to(&self, range: Range<usize>, f: [&mut [R]; 3]) {
        let end = range.end.min(self.runs.particles);
        (self.runs).add_sums(&self.bufs.blocks, range.start..end, f);
    }

    /// As [`TwoPasses::add_to`], but overwrites `f` (which needs no zeroing first): the
    /// same bits as adding to zeros. Particles past the springs' last one get zero.
    pub fn write_to(&self, range: Range<usize>, f: [&mut [R]; 3]) {
        let end = range.end.min(self.runs.particles).max(range.start);
        (self.runs).sum_blocks(&self.bufs.blocks, range.start..end, f, true);
    }
}

impl<R: Real> BlockPass<'_, R> {
    /// How many blocks there are to fill.
    pub fn len(&self) -> usize {
        self.runs.blocks.len()
    }

    /// Whether there is no block to fill (no springs).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Fills block `b`'s sums from positions and velocities `pos`, `vel` (all particles);
    /// nothing for a block past the last. Each block must be filled by one member only, and
    /// none may read the sums before all are filled.
    pub fn fill(&self, b: usize, pos: &Components<R>, vel: &Components<R>) {
        let runs = self.runs;
        let Some(block) = runs.blocks.get(b) else {
            return;
        };
        let pass = runs.force_pass(pos, vel);
        // SAFETY: block `b`'s buffer is filled by this member only (the contract above).
        runs.block_pass(block, unsafe { self.blocks.at(b) }, &pass);
    }
}
