//! The spring forces' fast path: springs regrouped into *runs* (consecutive first ends, one
//! index offset to the second end), evaluated over structure-of-arrays copies of the state.
//!
//! A grid cloth's springs fall into a few long runs per row (each stencil direction is one
//! offset), so the per-spring work is a straight loop over contiguous memory that the
//! compiler vectorises, and the scatter to both ends is two contiguous adds. An irregular
//! mesh gives short runs and still works, just with less to vectorise.
//!
//! Parallel without races and deterministic: the particles are cut into a number of blocks
//! that depends on the cloth's size only (never on the thread count), shared out between
//! the members of a [`Team`]. Each block's runs write
//! into the block's own buffer, which spans the block plus the reach of its longest offset;
//! then every particle adds the buffers that cover it, in block order. So 1, 2 or 64 threads
//! give bit-identical forces.

use std::ops::Range;

use glam::Vec3;

use crate::parallel::{Disjoint, PARALLEL_ELEMENTS, Team};
use crate::parallel::{wide, wide_fma};

use super::components::at;
use super::components::{Components, Scratch, split};
use super::run_pass::{ForcePass, ProductPass, Projectors, RunPass};
use crate::cloth::Real;

mod system;
pub use system::SystemSums;

/// Particles per block (a block is one parallel task).
const BLOCK: usize = 1024;
/// Blocks from which the blocks run in parallel (on the [`Team`]): as many as hold
/// [`PARALLEL_ELEMENTS`] particles (4 blocks, 64 × 64 particles), the point from which the
/// per-particle loops go parallel too.
const PARALLEL_BLOCKS: usize = PARALLEL_ELEMENTS / BLOCK;

/// Longest gap in a run filled with springs of no strength (rest length, stiffness and
/// damping 0: their force is exactly zero) rather than starting a new run.
const MAX_GAP: u32 = 8;
/// The run-order index of such a filler.
const GHOST: u32 = u32::MAX;

/// One chunk of forces for a gather.
struct Chunks<'a, 'b, T> {
    /// The particles it holds (`BLOCK` of them, fewer in the last chunk).
    particles: std::ops::Range<usize>,
    forces: &'a Disjoint<'b, T>,
}

/// Springs `start..start + len` (in run order) join `a + j` to `a + off + j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Run {
    a: u32,
    off: u32,
    start: u32,
    len: u32,
}

/// One block: its runs, its springs (a contiguous slice in run order) and the particles
/// its springs touch, `lo..hi`.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Block {
    runs: std::ops::Range<usize>,
    springs: std::ops::Range<usize>,
    pub(super) lo: usize,
    pub(super) hi: usize,
}

/// Springs regrouped for the fast path (see the module documentation), computing in `R`
/// (`f32` unless said otherwise).
#[derive(Clone, Debug, PartialEq)]
pub struct SpringRuns<R: Real = f32> {
    pub(super) particles: usize,
    /// For each place in run order, the index of its spring in the caller's arrays
    /// ([`GHOST`] for a filler).
    order: Vec<u32>,
    /// Blocks from which the blocks run in parallel ([`PARALLEL_BLOCKS`]; tests lower it).
    parallel_from: usize,
    rest: Vec<R>,
    k: Vec<R>,
    c: Vec<R>,
    runs: Vec<Run>,
    pub(super) blocks: Vec<Block>,
    pub(super) scratch: Scratch<Buffers<R>>,
}

#[derive(Debug, Default)]
pub(super) struct Buffers<R> {
    /// Positions and velocities, one array per component.
    pos: Components<R>,
    vel: Components<R>,
    /// Per block: its springs' forces summed over `lo..hi`.
    pub(super) blocks: Vec<BlockBuffers<R>>,
}

#[derive(Clone, Debug, Default)]
pub(super) struct BlockBuffers<R> {
    /// The sums at first ends (the block's sums are `first − second`, taken as they are
    /// gathered).
    first: Components<R>,
    /// The forces on second ends (subtracted), summed apart so that one vector loop adds at
    /// both ends of a run, however near its offset.
    second: Components<R>,
}

impl<R: Real> SpringRuns<R> {
    /// Springs `a[e]`–`b[e]` with rest length, stiffness and damping per spring, over
    /// `particles` particles. A spring from a particle to itself exerts no force and is
    /// left out.
    pub fn new(particles: usize, a: &[u32], b: &[u32], rest: &[R], k: &[R], c: &[R]) -> Self {
        // The force on the lower-numbered end is the same whichever end is called first.
        let mut order: Vec<(u32, u32, usize)> = (0..a.len())
            .filter(|&e| a[e] != b[e])
            .map(|e| {
                let (lo, hi) = (a[e].min(b[e]), a[e].max(b[e]));
                (hi - lo, lo, e)
            })
            .collect();
        // By block, then offset, then first end: runs never cross a block.
        order.sort_unstable_by_key(|&(off, lo, e)| (lo as usize / BLOCK, off, lo, e));
        let blocks_n = particles.div_ceil(BLOCK).max(1);
        let mut runs: Vec<Run> = Vec::new();
        let mut blocks = Vec::with_capacity(blocks_n);
        // Run order: each place's spring, or GHOST for a gap filled to join two runs.
        let mut placed: Vec<u32> = Vec::with_capacity(order.len() + order.len() / 8);
        let mut next = 0;
        for block in 0..blocks_n {
            let (first_run, first_spring) = (runs.len(), placed.len());
            let mut hi = (block + 1) * BLOCK;
            while let Some(&(off, lo, e)) = order.get(next) {
                if lo as usize / BLOCK != block {
                    break;
                }
                let in_block = runs.len() > first_run;
                match runs.last_mut() {
                    // A short gap in a run (a grid row's end) is filled with springs of no
                    // strength, so the row's run and the next one are one vector loop.
                    Some(r)
                        if in_block
                            && r.off == off
                            && lo >= r.a + r.len
                            && lo - (r.a + r.len) <= MAX_GAP =>
                    {
                        let gap = lo - (r.a + r.len);
                        placed.extend(std::iter::repeat_n(GHOST, gap as usize));
                        r.len += gap + 1;
                    }
                    _ => runs.push(Run {
                        a: lo,
                        off,
                        start: placed.len() as u32,
                        len: 1,
                    }),
                }
                placed.push(e as u32);
                hi = hi.max((lo + off) as usize + 1);
                next += 1;
            }
            let lo = block * BLOCK;
            blocks.push(Block {
                runs: first_run..runs.len(),
                springs: first_spring..placed.len(),
                lo: lo.min(particles),
                hi: hi.min(particles).max(lo.min(particles)),
            });
        }
        let mut runs = Self {
            particles,
            order: placed,
            parallel_from: PARALLEL_BLOCKS,
            rest: Vec::new(),
            k: Vec::new(),
            c: Vec::new(),
            runs,
            blocks,
            scratch: Scratch::default(),
        };
        runs.rest = runs.pick(rest);
        runs.set_strengths(k, c);
        runs
    }

    /// New stiffness and damping per spring (indexed as given to [`SpringRuns::new`]): the
    /// runs stay, only the values are put in run order again.
    pub fn set_strengths(&mut self, k: &[R], c: &[R]) {
        self.k = self.pick(k);
        self.c = self.pick(c);
    }

    /// `v` (per spring, in the caller's order) in run order; 0 for gap fillers.
    fn pick(&self, v: &[R]) -> Vec<R> {
        (self.order.iter())
            .map(|&e| if e == GHOST { R::ZERO } else { v[e as usize] })
            .collect()
    }

    /// Runs the blocks in parallel from `blocks` blocks on (tests take the parallel path on
    /// small cloths with 1).
    #[cfg(test)]
    fn parallel_from(mut self, blocks: usize) -> Self {
        self.parallel_from = blocks;
        self
    }

    /// How many runs the springs fell into (fewer is faster).
    #[cfg(test)]
    fn run_count(&self) -> usize {
        self.runs.len()
    }

    /// As [`SpringRuns::add_forces`] with positions, velocities and forces stored one array
    /// per component (no copies made): the same operations in the same order, so the same
    /// bits.
    pub fn add_forces_components(
        &self,
        pos: &Components<R>,
        vel: &Components<R>,
        f: &mut Components<R>,
    ) {
        let n = (pos.iter().chain(vel).map(Vec::len))
            .chain(f.iter().map(Vec::len))
            .fold(self.particles, usize::min);
        if self.runs.is_empty() || n < self.particles {
            return;
        }
        let mut buffers = self.scratch.lock();
        let blocks = &mut buffers.blocks;
        let pass = self.force_pass(pos, vel);
        self.block_sums(blocks, |block, buf| self.block_pass(block, buf, &pass));
        self.gather_components(blocks, f, n);
    }

    /// Adds every block's sums to `f` (the first `n` particles).
    fn gather_components(&self, blocks: &[BlockBuffers<R>], f: &mut Components<R>, n: usize) {
        let [fx, fy, fz] = f;
        let (fy, fz) = (Disjoint::new(&mut fy[..n]), Disjoint::new(&mut fz[..n]));
        self.each_chunk(
            n,
            |chunks| {
                let range = chunks.particles.clone();
                // SAFETY: each chunk is taken by one call only (see `each_chunk`).
                let out = unsafe {
                    [
                        chunks.forces.part(range.clone()),
                        fy.part(range.clone()),
                        fz.part(range.clone()),
                    ]
                };
                self.add_sums(blocks, range, out);
            },
            &mut fx[..n],
        );
    }

    /// Adds the blocks' sums over particles `range` to `out` (that range of the forces),
    /// each block's in block order.
    pub(super) fn add_sums(
        &self,
        blocks: &[BlockBuffers<R>],
        range: Range<usize>,
        out: [&mut [R]; 3],
    ) {
        self.sum_blocks(blocks, range, out, false);
    }

    /// As [`SpringRuns::add_sums`], but `write`: the first sum to reach each particle of
    /// `out` overwrites it (`0 + x`, the bits of adding to zero), and the particles past
    /// `range` (to the end of `out`) are set to zero; so `out` needs no zeroing first.
    pub(super) fn sum_blocks(
        &self,
        blocks: &[BlockBuffers<R>],
        range: Range<usize>,
        out: [&mut [R]; 3],
        write: bool,
    ) {
        wide(
            #[inline(always)]
            || self.sum_blocks_in(blocks, range, out, write),
        )
    }

    /// [`SpringRuns::sum_blocks`]'s work, inlined into its AVX2 build.
    #[inline(always)]
    fn sum_blocks_in(
        &self,
        blocks: &[BlockBuffers<R>],
        range: Range<usize>,
        out: [&mut [R]; 3],
        write: bool,
    ) {
        let [ox, oy, oz] = out;
        let len = ox.len().min(oy.len()).min(oz.len());
        // With `write`, the particles `..done` (from the range's start) have had a sum.
        let mut done = if write { 0 } else { len };
        self.cover_range(
            blocks,
            range,
            #[inline(always)]
            |at, first, second| {
                let end = at + first[0].len();
                // Each block reaches from its first particle to at least the next block's: they
                // leave no gap.
                debug_assert!(done >= at, "a gap before {at}");
                let outs = [&mut *ox, &mut *oy, &mut *oz].into_iter();
                for (out, (s, t)) in outs.zip(first.into_iter().zip(second)) {
                    let fresh = done.clamp(at, end) - at;
                    let (added, written) = out[at..end].split_at_mut(fresh);
                    for ((o, &s), &t) in added.iter_mut().zip(s).zip(t) {
                        *o += s - t;
                    }
                    let (s, t) = (&s[fresh..], &t[fresh..]);
                    for ((o, &s), &t) in written.iter_mut().zip(s).zip(t) {
                        *o = R::ZERO + (s - t);
                    }
                }
                done = done.max(end);
            },
        );
        for out in [ox, oy, oz] {
            out[done.min(len)..len].fill(R::ZERO);
        }
    }

    /// Calls `gather` for each `BLOCK`-particle chunk of `forces` (the first `n` particles'
    /// forces): one chunk a piece of a team section ([`Team::run_pieces_if`]) when the
    /// blocks are many enough; every chunk's sum is the same whoever takes it.
    fn each_chunk<T: Send>(
        &self,
        n: usize,
        gather: impl Fn(Chunks<'_, '_, T>) + Sync,
        forces: &mut [T],
    ) {
        let forces = Disjoint::new(forces);
        (Team::current()).run_pieces_if(self.parallel(), n.div_ceil(BLOCK), &|_, c| {
            gather(Chunks {
                particles: c * BLOCK..((c + 1) * BLOCK).min(n),
                forces: &forces,
            })
        });
    }

    /// Whether the blocks are many enough to run in parallel.
    fn parallel(&self) -> bool {
        self.blocks.len() >= self.parallel_from
    }

    /// Every block's sums by `pass` (which fills one block's buffers), one block a piece of a
    /// team section ([`Team::run_pieces_if`]) when they are many enough.
    fn block_sums(
        &self,
        bufs: &mut Vec<BlockBuffers<R>>,
        pass: impl Fn(&Block, &mut BlockBuffers<R>) + Sync,
    ) {
        self.size_buffers(bufs);
        let bufs = Disjoint::new(&mut bufs[..]);
        (Team::current()).run_pieces_if(self.parallel(), self.blocks.len(), &|_, b| {
            // SAFETY: each piece runs once, so each block's buffer has one member.
            pass(&self.blocks[b], unsafe { bufs.at(b) })
        });
    }

    /// One buffer per block, each as long as the block's reach.
    pub(super) fn size_buffers(&self, bufs: &mut Vec<BlockBuffers<R>>) {
        bufs.resize_with(self.blocks.len(), Default::default);
        for (buf, block) in bufs.iter_mut().zip(&self.blocks) {
            for sums in buf.first.iter_mut().chain(&mut buf.second) {
                sums.resize(block.hi - block.lo, R::ZERO);
            }
        }
    }

    /// The spring forces' pass over positions `p` and velocities `v` (all particles).
    pub(super) fn force_pass<'a>(
        &'a self,
        p: &'a Components<R>,
        v: &'a Components<R>,
    ) -> ForcePass<'a, R> {
        ForcePass {
            rest: &self.rest,
            k: &self.k,
            c: &self.c,
            p,
            v,
        }
    }

    /// Calls `add(at, first, second)` for each block's buffers over the particles `lo..hi`
    /// (its sums are `first − second`), in block order; `at` is where from `lo` they start.
    #[inline(always)]
    fn cover_range(
        &self,
        buffers: &[BlockBuffers<R>],
        std::ops::Range { start: lo, end: hi }: std::ops::Range<usize>,
        mut add: impl FnMut(usize, [&[R]; 3], [&[R]; 3]),
    ) {
        let blocks = self.blocks.iter().zip(buffers);
        for (b, buf) in blocks.take_while(|(b, _)| b.lo < hi) {
            let (from, to) = (lo.max(b.lo), hi.min(b.hi));
            if from < to {
                let range = from - b.lo..to - b.lo;
                add(from - lo, at(&buf.first, &range), at(&buf.second, &range));
            }
        }
    }

    /// One block's sums by `pass`, run by run (see [`SpringRuns::each_run`]), compiled for
    /// AVX2 with FMA where the CPU has them ([`wide_fma`]): the same bits either way.
    pub(super) fn block_pass(
        &self,
        block: &Block,
        buf: &mut BlockBuffers<R>,
        pass: &impl RunPass<R>,
    ) {
        wide_fma(
            #[inline(always)]
            || self.each_run(block, buf, pass),
        )
    }

    /// Fills one block's buffers: [`RunPass::run`] for each of its runs. The first run
    /// writes its slices of them rather than adding to them, so only the rest of them is
    /// zeroed first.
    #[inline(always)]
    fn each_run(&self, block: &Block, buf: &mut BlockBuffers<R>, pass: &impl RunPass<R>) {
        let BlockBuffers { first, second } = buf;
        let Some((lead, rest)) = self.runs[block.runs.clone()].split_first() else {
            first
                .iter_mut()
                .chain(second.iter_mut())
                .for_each(|s| s.fill(R::ZERO));
            return;
        };
        let [at_a, at_b] = Self::slices(block, lead);
        for (buffer, written) in [(&mut *first, at_a), (&mut *second, at_b)] {
            for s in buffer {
                s[..written.start].fill(R::ZERO);
                s[written.end..].fill(R::ZERO);
            }
        }
        self.one_run::<true>(block, lead, first, second, pass);
        for r in rest {
            self.one_run::<false>(block, r, first, second, pass);
        }
    }

    /// Where run `r` lands in its block's buffers: at its first ends and at its second.
    #[inline(always)]
    fn slices(block: &Block, r: &Run) -> [Range<usize>; 2] {
        let (a, off, len) = (r.a as usize - block.lo, r.off as usize, r.len as usize);
        [a..a + len, a + off..a + off + len]
    }

    /// Run `r` of `block` by `pass`, written into its slices of the buffers (`WRITE`) or
    /// added to them.
    #[inline(always)]
    fn one_run<const WRITE: bool>(
        &self,
        block: &Block,
        r: &Run,
        first: &mut Components<R>,
        second: &mut Components<R>,
        pass: &impl RunPass<R>,
    ) {
        let (a, off, len) = (r.a as usize, r.off as usize, r.len as usize);
        let springs = r.start as usize..r.start as usize + len;
        let ends = [a..a + len, a + off..a + off + len];
        let [at_a, at_b] = Self::slices(block, r);
        let [s0, s1, s2] = first;
        let [t0, t1, t2] = second;
        pass.run::<WRITE>(
            ends,
            springs,
            [&mut s0[at_a.clone()], &mut s1[at_a.clone()], &mut s2[at_a]],
            [&mut t0[at_b.clone()], &mut t1[at_b.clone()], &mut t2[at_b]],
        );
    }

    /// `K` numbers per spring (`value(e)` for spring `e` as given to [`SpringRuns::new`]) in
    /// run order, one array each, zero for gap fillers (tests put blocks of their own in
    /// run order with it).
    #[cfg(test)]
    pub fn in_order<const K: usize>(&self, value: impl Fn(usize) -> [R; K], out: &mut [Vec<R>; K]) {
        let n = self.order.len();
        for entry in out.iter_mut() {
            entry.clear();
            entry.resize(n, R::ZERO);
        }
        for (i, &e) in self.order.iter().enumerate() {
            if e != GHOST {
                for (entry, v) in out.iter_mut().zip(value(e as usize)) {
                    entry[i] = v;
                }
            }
        }
    }

    /// Adds `Σ_e S_e·u_other` to `out` at both ends of every spring `e`, with
    /// `S_e = α·I + β·n nᵀ` as [`SpringRuns::add_system_blocks`] puts them in run order
    /// (`[α, β, n.x, n.y, n.z]`): the off-diagonal part of a matrix-vector product with the
    /// implicit system (whose off-diagonal blocks are `−S_e`). In parallel as the forces
    /// are, with the same result on any number of threads.
    pub fn add_block_products(
        &self,
        s: &Projectors<R>,
        u: &Components<R>,
        out: &mut Components<R>,
    ) {
        let n = (u.iter().chain(out.iter()).map(Vec::len)).fold(self.particles, usize::min);
        if self.runs.is_empty() || n < self.particles || s[0].len() != self.order.len() {
            return;
        }
        let mut buffers = self.scratch.lock();
        let blocks = &mut buffers.blocks;
        let pass = ProductPass { s, u };
        self.block_sums(blocks, |block, buf| self.block_pass(block, buf, &pass));
        self.gather_components(blocks, out, n);
    }
}

/// The `f32` runs also take the state as vectors.
impl SpringRuns {
    /// Adds every spring's force (N) to `f` (indexed by particle).
    pub fn add_forces(&self, pos: &[Vec3], vel: &[Vec3], f: &mut [Vec3]) {
        let n = self.particles.min(pos.len()).min(vel.len()).min(f.len());
        if self.runs.is_empty() || n < self.particles {
            return;
        }
        let mut buffers = self.scratch.lock();
        let bufs = &mut *buffers;
        split(pos, &mut bufs.pos, n);
        split(vel, &mut bufs.vel, n);
        let (p, v) = (&bufs.pos, &bufs.vel);
        self.block_sums(&mut bufs.blocks, |block, buf| {
            self.block_pass(block, buf, &self.force_pass(p, v))
        });
        let blocks = &bufs.blocks;
        self.each_chunk(
            n,
            |chunks| {
                // SAFETY: each chunk is taken by one call only (see `each_chunk`).
                let out = unsafe { chunks.forces.part(chunks.particles.clone()) };
                self.cover_range(
                    blocks,
                    chunks.particles,
                    |at, [sx, sy, sz], [tx, ty, tz]| {
                        for (j, o) in out[at..at + sx.len()].iter_mut().enumerate() {
                            *o += Vec3::new(sx[j] - tx[j], sy[j] - ty[j], sz[j] - tz[j]);
                        }
                    },
                );
            },
            &mut f[..n],
        );
    }
}

#[cfg(test)]
mod tests;
