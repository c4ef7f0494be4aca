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

use super::super::team::{Disjoint, PARALLEL_ELEMENTS, Team};
use super::super::wide::{wide, wide_fma};
use super::components::{Components, Scratch, split};
use std::ops::Range;

use glam::Vec3;

/// Springs' system blocks `α·I + β·n nᵀ` in run order: `[α, β, n.x, n.y, n.z]`
/// ([`SpringBlock::numbers`](super::SpringBlock::numbers)), one array each
/// ([`SpringRuns::add_block_products`]).
pub type Projectors = [Vec<f32>; 5];

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
struct Run {
    a: u32,
    off: u32,
    start: u32,
    len: u32,
}

/// One block: its runs, its springs (a contiguous slice in run order) and the particles
/// its springs touch, `lo..hi`.
#[derive(Clone, Debug, PartialEq)]
struct Block {
    runs: std::ops::Range<usize>,
    springs: std::ops::Range<usize>,
    lo: usize,
    hi: usize,
}

/// Springs regrouped for the fast path (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct SpringRuns {
    particles: usize,
    /// For each place in run order, the index of its spring in the caller's arrays
    /// ([`GHOST`] for a filler).
    order: Vec<u32>,
    /// Blocks from which the blocks run in parallel ([`PARALLEL_BLOCKS`]; tests lower it).
    parallel_from: usize,
    rest: Vec<f32>,
    k: Vec<f32>,
    c: Vec<f32>,
    runs: Vec<Run>,
    blocks: Vec<Block>,
    scratch: Scratch<Buffers>,
}

#[derive(Debug, Default)]
struct Buffers {
    /// Positions and velocities, one array per component.
    pos: Components,
    vel: Components,
    /// Per block: its springs' forces summed over `lo..hi`.
    blocks: Vec<BlockBuffers>,
}

#[derive(Clone, Debug, Default)]
struct BlockBuffers {
    /// The sums at first ends (the block's sums are `first − second`, taken as they are
    /// gathered).
    first: Components,
    /// The forces on second ends (subtracted), summed apart so that one vector loop adds at
    /// both ends of a run, however near its offset.
    second: Components,
}

impl SpringRuns {
    /// Springs `a[e]`–`b[e]` with rest length, stiffness and damping per spring, over
    /// `particles` particles. A spring from a particle to itself exerts no force and is
    /// left out.
    pub fn new(particles: usize, a: &[u32], b: &[u32], rest: &[f32], k: &[f32], c: &[f32]) -> Self {
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
    pub fn set_strengths(&mut self, k: &[f32], c: &[f32]) {
        self.k = self.pick(k);
        self.c = self.pick(c);
    }

    /// `v` (per spring, in the caller's order) in run order; 0 for gap fillers.
    fn pick(&self, v: &[f32]) -> Vec<f32> {
        (self.order.iter())
            .map(|&e| if e == GHOST { 0.0 } else { v[e as usize] })
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
            self.block_pass(block, buf, &ForcePass { runs: self, p, v })
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

    /// As [`SpringRuns::add_forces`] with positions, velocities and forces stored one array
    /// per component (no copies made): the same operations in the same order, so the same
    /// bits.
    pub fn add_forces_components(&self, pos: &Components, vel: &Components, f: &mut Components) {
        let n = (pos.iter().chain(vel).map(Vec::len))
            .chain(f.iter().map(Vec::len))
            .fold(self.particles, usize::min);
        if self.runs.is_empty() || n < self.particles {
            return;
        }
        let mut buffers = self.scratch.lock();
        let blocks = &mut buffers.blocks;
        let pass = ForcePass {
            runs: self,
            p: pos,
            v: vel,
        };
        self.block_sums(blocks, |block, buf| self.block_pass(block, buf, &pass));
        self.gather_components(blocks, f, n);
    }

    /// Adds every block's sums to `f` (the first `n` particles).
    fn gather_components(&self, blocks: &[BlockBuffers], f: &mut Components, n: usize) {
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
    fn add_sums(&self, blocks: &[BlockBuffers], range: Range<usize>, out: [&mut [f32]; 3]) {
        self.sum_blocks(blocks, range, out, false);
    }

    /// As [`SpringRuns::add_sums`], but `write`: the first sum to reach each particle of
    /// `out` overwrites it (`0 + x`, the bits of adding to zero), and the particles past
    /// `range` (to the end of `out`) are set to zero; so `out` needs no zeroing first.
    fn sum_blocks(
        &self,
        blocks: &[BlockBuffers],
        range: Range<usize>,
        out: [&mut [f32]; 3],
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
        blocks: &[BlockBuffers],
        range: Range<usize>,
        out: [&mut [f32]; 3],
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
                        *o = 0.0 + (s - t);
                    }
                }
                done = done.max(end);
            },
        );
        for out in [ox, oy, oz] {
            out[done.min(len)..len].fill(0.0);
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
        bufs: &mut Vec<BlockBuffers>,
        pass: impl Fn(&Block, &mut BlockBuffers) + Sync,
    ) {
        self.size_buffers(bufs);
        let bufs = Disjoint::new(&mut bufs[..]);
        (Team::current()).run_pieces_if(self.parallel(), self.blocks.len(), &|_, b| {
            // SAFETY: each piece runs once, so each block's buffer has one member.
            pass(&self.blocks[b], unsafe { bufs.at(b) })
        });
    }

    /// One buffer per block, each as long as the block's reach.
    fn size_buffers(&self, bufs: &mut Vec<BlockBuffers>) {
        bufs.resize_with(self.blocks.len(), Default::default);
        for (buf, block) in bufs.iter_mut().zip(&self.blocks) {
            for sums in buf.first.iter_mut().chain(&mut buf.second) {
                sums.resize(block.hi - block.lo, 0.0);
            }
        }
    }

    /// The forces in two passes, for a caller that runs them in its own team sections
    /// between other work (see [`ForceSet`](super::ForceSet)'s fused path): the buffers stay
    /// locked until the result is dropped. The same operations as
    /// [`SpringRuns::add_forces_components`], so the same bits.
    pub fn two_passes(&self) -> TwoPasses<'_> {
        let mut bufs = self.scratch.lock();
        self.size_buffers(&mut bufs.blocks);
        TwoPasses { runs: self, bufs }
    }

    /// Calls `add(at, first, second)` for each block's buffers over the particles `lo..hi`
    /// (its sums are `first − second`), in block order; `at` is where from `lo` they start.
    #[inline(always)]
    fn cover_range(
        &self,
        buffers: &[BlockBuffers],
        std::ops::Range { start: lo, end: hi }: std::ops::Range<usize>,
        mut add: impl FnMut(usize, [&[f32]; 3], [&[f32]; 3]),
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
    fn block_pass(&self, block: &Block, buf: &mut BlockBuffers, pass: &impl RunPass) {
        wide_fma(
            #[inline(always)]
            || self.each_run(block, buf, pass),
        )
    }

    /// Fills one block's buffers: [`RunPass::run`] for each of its runs. The first run
    /// writes its slices of them rather than adding to them, so only the rest of them is
    /// zeroed first.
    #[inline(always)]
    fn each_run(&self, block: &Block, buf: &mut BlockBuffers, pass: &impl RunPass) {
        let BlockBuffers { first, second } = buf;
        let Some((lead, rest)) = self.runs[block.runs.clone()].split_first() else {
            first
                .iter_mut()
                .chain(second.iter_mut())
                .for_each(|s| s.fill(0.0));
            return;
        };
        let [at_a, at_b] = Self::slices(block, lead);
        for (buffer, written) in [(&mut *first, at_a), (&mut *second, at_b)] {
            for s in buffer {
                s[..written.start].fill(0.0);
                s[written.end..].fill(0.0);
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
        first: &mut Components,
        second: &mut Components,
        pass: &impl RunPass,
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
    /// run order, one array each, zero for gap fillers.
    pub fn in_order<const K: usize>(
        &self,
        value: impl Fn(usize) -> [f32; K],
        out: &mut [Vec<f32>; K],
    ) {
        let n = self.order.len();
        for entry in out.iter_mut() {
            entry.clear();
            entry.resize(n, 0.0);
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
    /// `S_e = α·I + β·n nᵀ` as put in run order by [`SpringRuns::in_order`]
    /// (`[α, β, n.x, n.y, n.z]`): the off-diagonal part of a matrix-vector product with the
    /// implicit system (whose off-diagonal blocks are `−S_e`). In parallel as the forces
    /// are, with the same result on any number of threads.
    pub fn add_block_products(&self, s: &Projectors, u: &Components, out: &mut Components) {
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

/// The spring forces in two passes ([`SpringRuns::two_passes`]): first every block's sums
/// ([`TwoPasses::blocks`], shared out by blocks), then, per range of particles, their sum
/// ([`TwoPasses::add_to`]).
pub struct TwoPasses<'a> {
    runs: &'a SpringRuns,
    bufs: std::sync::MutexGuard<'a, Buffers>,
}

/// The first pass of [`TwoPasses`], which team members share by blocks.
pub struct BlockPass<'a> {
    runs: &'a SpringRuns,
    blocks: Disjoint<'a, BlockBuffers>,
}

impl TwoPasses<'_> {
    /// Whether positions and velocities of `n` particles reach every spring's ends.
    pub fn fits(&self, n: usize) -> bool {
        n >= self.runs.particles
    }

    /// The first pass, for the members of a section to share.
    pub fn blocks(&mut self) -> BlockPass<'_> {
        BlockPass {
            runs: self.runs,
            blocks: Disjoint::new(&mut self.bufs.blocks[..]),
        }
    }

    /// Adds the forces on particles `range` to `f` (that range of the forces): each block's
    /// sums in block order, as [`SpringRuns::add_forces_components`] does. Particles past
    /// the springs' last one get nothing.
    pub fn add_to(&self, range: Range<usize>, f: [&mut [f32]; 3]) {
        let end = range.end.min(self.runs.particles);
        (self.runs).add_sums(&self.bufs.blocks, range.start..end, f);
    }

    /// As [`TwoPasses::add_to`], but overwrites `f` (which needs no zeroing first): the
    /// same bits as adding to zeros. Particles past the springs' last one get zero.
    pub fn write_to(&self, range: Range<usize>, f: [&mut [f32]; 3]) {
        let end = range.end.min(self.runs.particles).max(range.start);
        (self.runs).sum_blocks(&self.bufs.blocks, range.start..end, f, true);
    }
}

impl BlockPass<'_> {
    /// How many blocks there are to fill.
    pub fn len(&self) -> usize {
        self.runs.blocks.len()
    }

    /// Fills block `b`'s sums from positions and velocities `pos`, `vel` (all particles);
    /// nothing for a block past the last. Each block must be filled by one member only, and
    /// none may read the sums before all are filled.
    pub fn fill(&self, b: usize, pos: &Components, vel: &Components) {
        let runs = self.runs;
        let Some(block) = runs.blocks.get(b) else {
            return;
        };
        let pass = ForcePass {
            runs,
            p: pos,
            v: vel,
        };
        // SAFETY: block `b`'s buffer is filled by this member only (the contract above).
        runs.block_pass(block, unsafe { self.blocks.at(b) }, &pass);
    }
}

/// What a block pass does with each run: `run` gets the run's two ranges of ends, its
/// springs (run order) and its slices of the block's buffers at its first ends and at its
/// second ends (where what it puts is subtracted), which it overwrites (`WRITE`: `0 + x`,
/// the bits of adding to zero) or adds to.
trait RunPass: Sync {
    fn run<const WRITE: bool>(
        &self,
        ends: [Range<usize>; 2],
        springs: Range<usize>,
        first: [&mut [f32]; 3],
        second: [&mut [f32]; 3],
    );
}

/// The spring forces (see [`kernel`]).
struct ForcePass<'a> {
    runs: &'a SpringRuns,
    p: &'a Components,
    v: &'a Components,
}

impl RunPass for ForcePass<'_> {
    #[inline(always)]
    fn run<const WRITE: bool>(
        &self,
        [ea, eb]: [Range<usize>; 2],
        springs: Range<usize>,
        first: [&mut [f32]; 3],
        second: [&mut [f32]; 3],
    ) {
        let (p, v, r) = (self.p, self.v, self.runs);
        kernel::<WRITE>(
            at(p, &ea),
            at(p, &eb),
            at(v, &ea),
            at(v, &eb),
            [
                &r.rest[springs.clone()],
                &r.k[springs.clone()],
                &r.c[springs],
            ],
            first,
            second,
        );
    }
}

/// Block products `S_e·u_other` at both ends (see [`SpringRuns::add_block_products`]).
struct ProductPass<'a> {
    s: &'a Projectors,
    u: &'a Components,
}

impl RunPass for ProductPass<'_> {
    #[inline(always)]
    fn run<const WRITE: bool>(
        &self,
        [ea, eb]: [Range<usize>; 2],
        springs: Range<usize>,
        first: [&mut [f32]; 3],
        second: [&mut [f32]; 3],
    ) {
        let (s, u) = (self.s, self.u);
        let n = springs.len();
        let [al, be, nx, ny, nz]: [&[f32]; 5] =
            std::array::from_fn(|k| &s[k][springs.clone()][..n]);
        let [ax, ay, az] = at(u, &(ea.start..ea.start + n));
        let [bx, by, bz] = at(u, &(eb.start..eb.start + n));
        let [f0, f1, f2] = first;
        let [t0, t1, t2] = second;
        let (f0, f1, f2) = (&mut f0[..n], &mut f1[..n], &mut f2[..n]);
        let (t0, t1, t2) = (&mut t0[..n], &mut t1[..n], &mut t2[..n]);
        let was = |o: f32| if WRITE { 0.0 } else { o };
        for j in 0..n {
            // S·w = α·w + β(n·w)·n.
            let db = be[j] * (nx[j] * bx[j] + ny[j] * by[j] + nz[j] * bz[j]);
            f0[j] = was(f0[j]) + (al[j] * bx[j] + db * nx[j]);
            f1[j] = was(f1[j]) + (al[j] * by[j] + db * ny[j]);
            f2[j] = was(f2[j]) + (al[j] * bz[j] + db * nz[j]);
            let da = be[j] * (nx[j] * ax[j] + ny[j] * ay[j] + nz[j] * az[j]);
            // Subtracted when gathered.
            t0[j] = was(t0[j]) - (al[j] * ax[j] + da * nx[j]);
            t1[j] = was(t1[j]) - (al[j] * ay[j] + da * ny[j]);
            t2[j] = was(t2[j]) - (al[j] * az[j] + da * nz[j]);
        }
    }
}

/// The particles `range` of each component.
#[inline(always)]
fn at<'a>(c: &'a Components, range: &Range<usize>) -> [&'a [f32]; 3] {
    [
        &c[0][range.clone()],
        &c[1][range.clone()],
        &c[2][range.clone()],
    ]
}

/// The force on each spring's first end, for springs whose ends' positions and velocities
/// are given per component: `[k(|d| − l₀) + c(v_b − v_a)·d̂] d̂`, zero for coincident ends;
/// added to `first` (at the first ends) and to `second` (at the second ends, where it is
/// subtracted later). Computed as `g·d` with `g = [k(|d| − l₀) + c((v_b − v_a)·d)/|d|]/|d|`,
/// with fused multiply-adds: 27 operations a spring where `n = d/|d|` first took 36.
/// `WRITE`: overwrites `first` and `second` instead (with `g·d + 0`, the same bits as
/// adding to zeroed sums).
#[inline(always)]
fn kernel<const WRITE: bool>(
    xa: [&[f32]; 3],
    xb: [&[f32]; 3],
    va: [&[f32]; 3],
    vb: [&[f32]; 3],
    params: [&[f32]; 3],
    first: [&mut [f32]; 3],
    second: [&mut [f32]; 3],
) {
    let n = first[0].len();
    let [ox, oy, oz] = first;
    let (ox, oy, oz) = (&mut ox[..n], &mut oy[..n], &mut oz[..n]);
    let [tx, ty, tz] = second;
    let (tx, ty, tz) = (&mut tx[..n], &mut ty[..n], &mut tz[..n]);
    let (xax, xay, xaz) = (&xa[0][..n], &xa[1][..n], &xa[2][..n]);
    let (xbx, xby, xbz) = (&xb[0][..n], &xb[1][..n], &xb[2][..n]);
    let (vax, vay, vaz) = (&va[0][..n], &va[1][..n], &va[2][..n]);
    let (vbx, vby, vbz) = (&vb[0][..n], &vb[1][..n], &vb[2][..n]);
    let (rest, k, c) = (&params[0][..n], &params[1][..n], &params[2][..n]);
    for j in 0..n {
        let (dx, dy, dz) = (xbx[j] - xax[j], xby[j] - xay[j], xbz[j] - xaz[j]);
        let len = dz.mul_add(dz, dy.mul_add(dy, dx * dx)).sqrt();
        let inv = if len > 1e-9 { 1.0 / len } else { 0.0 };
        let (ux, uy, uz) = (vbx[j] - vax[j], vby[j] - vay[j], vbz[j] - vaz[j]);
        let along = uz.mul_add(dz, uy.mul_add(dy, ux * dx));
        let s = c[j].mul_add(along * inv, k[j] * (len - rest[j]));
        let g = s * inv;
        let was = |o: f32| if WRITE { 0.0 } else { o };
        ox[j] = g.mul_add(dx, was(ox[j]));
        oy[j] = g.mul_add(dy, was(oy[j]));
        oz[j] = g.mul_add(dz, was(oz[j]));
        tx[j] = g.mul_add(dx, was(tx[j]));
        ty[j] = g.mul_add(dy, was(ty[j]));
        tz[j] = g.mul_add(dz, was(tz[j]));
    }
}

#[cfg(test)]
mod tests {
    use super::super::jacobian::SpringBlock;
    use super::*;

    /// The plain spring formula, spring by spring.
    fn reference(
        a: &[u32],
        b: &[u32],
        rest: &[f32],
        k: &[f32],
        c: &[f32],
        pos: &[Vec3],
        vel: &[Vec3],
    ) -> Vec<Vec3> {
        let mut f = vec![Vec3::ZERO; pos.len()];
        for e in 0..a.len() {
            let (ia, ib) = (a[e] as usize, b[e] as usize);
            let d = pos[ib] - pos[ia];
            let len = d.length();
            if len > 1e-9 {
                let n = d / len;
                let t = (k[e] * (len - rest[e]) + c[e] * (vel[ib] - vel[ia]).dot(n)) * n;
                f[ia] += t;
                f[ib] -= t;
            }
        }
        f
    }

    /// The springs of a `w` × `h` grid's stencil `offsets` (columns, rows), from each
    /// particle to its neighbour.
    fn stencil(w: usize, h: usize, offsets: &[(usize, usize)]) -> (Vec<u32>, Vec<u32>) {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for p in 0..w * h {
            for &(di, dj) in offsets {
                let (i, j) = (p % w + di, p / w + dj);
                if i < w && j < h {
                    a.push(p as u32);
                    b.push((j * w + i) as u32);
                }
            }
        }
        (a, b)
    }

    /// `start` plus the forces, computed on component arrays.
    fn on_components(runs: &SpringRuns, pos: &[Vec3], vel: &[Vec3], start: &[Vec3]) -> Vec<Vec3> {
        let n = pos.len();
        let (mut p, mut v, mut f) = <(Components, Components, Components)>::default();
        split(pos, &mut p, n);
        split(vel, &mut v, n);
        split(start, &mut f, n);
        runs.add_forces_components(&p, &v, &mut f);
        (0..n)
            .map(|i| Vec3::new(f[0][i], f[1][i], f[2][i]))
            .collect()
    }

    /// A scrambled cloth: a grid's stencil springs (long runs) plus random ones (runs of
    /// one), in shuffled order and with ends swapped, over several blocks.
    #[test]
    fn runs_give_the_springs_forces_on_any_layout() {
        let (w, h) = (70usize, 40usize);
        let n = w * h;
        let mut rnd = crate::test_rng::uniform(12345);
        let pos: Vec<Vec3> = (0..n)
            .map(|p| {
                Vec3::new((p % w) as f32 * 0.01, (p / w) as f32 * -0.01, 0.0)
                    + 0.002 * Vec3::new(rnd(), rnd(), rnd())
            })
            .collect();
        let vel: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(rnd(), rnd(), rnd()) - 0.5)
            .collect();
        let (mut a, mut b) = stencil(w, h, &[(1, 0), (0, 1), (1, 1), (2, 0)]);
        for _ in 0..500 {
            a.push((rnd() * n as f32) as u32 % n as u32);
            b.push((rnd() * n as f32) as u32 % n as u32);
        }
        // Shuffle and swap ends.
        for e in (1..a.len()).rev() {
            let o = (rnd() * e as f32) as usize;
            a.swap(e, o);
            b.swap(e, o);
            if rnd() < 0.5 {
                std::mem::swap(&mut a[e], &mut b[e]);
            }
        }
        let rest: Vec<f32> = a
            .iter()
            .zip(&b)
            .map(|(&i, &j)| pos[i as usize].distance(pos[j as usize]) * (0.9 + 0.2 * rnd()))
            .collect();
        let k: Vec<f32> = (0..a.len()).map(|_| 100.0 + 400.0 * rnd()).collect();
        let c: Vec<f32> = (0..a.len()).map(|_| 0.05 * rnd()).collect();
        let runs = SpringRuns::new(n, &a, &b, &rest, &k, &c);
        assert!(runs.blocks.len() >= 3, "the test spans several blocks");
        assert!(
            runs.run_count() < a.len() / 5,
            "grid springs fall into long runs"
        );
        let want = reference(&a, &b, &rest, &k, &c, &pos, &vel);
        let start = vec![Vec3::new(0.5, -1.0, 2.0); n];
        let mut got = start.clone();
        runs.add_forces(&pos, &vel, &mut got);
        let scale = want.iter().map(|f| f.length()).fold(0.0, f32::max);
        for p in 0..n {
            let err = (got[p] - start[p] - want[p]).length();
            assert!(
                err <= 1e-5 * scale,
                "particle {p}: {} vs {}",
                got[p] - start[p],
                want[p]
            );
        }
        // The same again (buffers reused), and with the blocks in parallel on one thread and
        // on two: identical bits.
        let mut again = start.clone();
        runs.add_forces(&pos, &vel, &mut again);
        assert!(got == again, "a rerun changed the forces");
        for threads in [1, 2] {
            // A fresh copy: no sums left over from another run can hide a block not done.
            let parallel = runs.clone().parallel_from(1);
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut out = start.clone();
            pool.install(|| parallel.add_forces(&pos, &vel, &mut out));
            assert!(
                got == out,
                "parallel blocks on {threads} threads changed the forces"
            );
            let fresh = runs.clone().parallel_from(1);
            let out = pool.install(|| on_components(&fresh, &pos, &vel, &start));
            assert!(got == out, "on components, {threads} threads");
        }
        // On component arrays: the same bits.
        assert!(got == on_components(&runs, &pos, &vel, &start));
        // Buffers reused at another state: the forces there, as from runs never used (each
        // block's first run overwrites its slices, the rest of its buffers is zeroed).
        let moved: Vec<Vec3> = (pos.iter().enumerate())
            .map(|(p, x)| *x * 1.02 + Vec3::new(0.0, 0.0, 0.001 * (p % 3) as f32))
            .collect();
        let (mut reused, mut fresh) = (start.clone(), start.clone());
        runs.add_forces(&moved, &vel, &mut reused);
        SpringRuns::new(n, &a, &b, &rest, &k, &c).add_forces(&moved, &vel, &mut fresh);
        assert!(
            reused == fresh,
            "sums of the last state stayed in the buffers"
        );
        assert!(reused != got, "the moved state gave the same forces");
        // New strengths without rebuilding the runs: the same as runs built with them.
        let stiffer: Vec<f32> = k.iter().map(|k| 2.0 * k).collect();
        let mut changed = runs.clone();
        changed.set_strengths(&stiffer, &c);
        let rebuilt = SpringRuns::new(n, &a, &b, &rest, &stiffer, &c);
        let (mut x, mut y) = (start.clone(), start.clone());
        changed.add_forces(&pos, &vel, &mut x);
        rebuilt.add_forces(&pos, &vel, &mut y);
        assert!(x == y, "new strengths differ from runs built with them");
        assert!(x != got, "the strengths changed nothing");
    }

    /// Springs of a `w` × `h` grid's stencil `offsets`, 1 cm apart with jittered depths,
    /// rest lengths and velocities (from `seed`), and their positions and velocities on
    /// component arrays.
    fn jittered_grid(
        w: usize,
        h: usize,
        seed: u64,
        offsets: &[(usize, usize)],
    ) -> (SpringRuns, Components, Components) {
        let n = w * h;
        let mut rnd = crate::test_rng::uniform(seed);
        let pos: Vec<Vec3> = (0..n)
            .map(|p| Vec3::new((p % w) as f32, -((p / w) as f32), rnd()) * 0.01)
            .collect();
        let vel: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
        let (a, b) = stencil(w, h, offsets);
        let rest: Vec<f32> = (0..a.len()).map(|_| 0.008 + 0.01 * rnd()).collect();
        let (k, c) = (vec![400.0; a.len()], vec![0.02; a.len()]);
        let (mut p, mut v) = (Components::default(), Components::default());
        split(&pos, &mut p, n);
        split(&vel, &mut v, n);
        (SpringRuns::new(n, &a, &b, &rest, &k, &c), p, v)
    }

    /// The block passes compiled plainly and for AVX2 with FMA (the one the CPU runs)
    /// give the same bits: the fused multiply-adds are exact either way. (On a CPU without
    /// AVX2 and FMA both sides are the plain build, and this proves nothing there; CI's
    /// machines have both.)
    #[test]
    fn the_plain_and_the_vector_build_give_the_same_bits() {
        let (runs, p, v) = jittered_grid(40, 30, 7, &[(1, 0), (0, 1), (1, 1), (0, 2)]);
        let pass = ForcePass {
            runs: &runs,
            p: &p,
            v: &v,
        };
        let mut buffers = Vec::new();
        runs.size_buffers(&mut buffers);
        let mut plain = buffers.clone();
        for (block, (buf, twin)) in runs.blocks.iter().zip(buffers.iter_mut().zip(&mut plain)) {
            runs.block_pass(block, buf, &pass);
            runs.each_run(block, twin, &pass);
            assert!(
                buf.first == twin.first && buf.second == twin.second,
                "block at {}",
                block.lo
            );
        }
        assert!(
            buffers[0].first[0].iter().any(|&f| f != 0.0),
            "no forces at all"
        );
    }

    /// [`TwoPasses::write_to`] overwrites what was there with the bits
    /// [`TwoPasses::add_to`] adds to zeros: over ranges that start and end inside blocks,
    /// span several, and reach past the last particle (which get zero).
    #[test]
    fn written_sums_are_the_added_ones_whatever_was_there() {
        let (runs, p, v) = jittered_grid(70, 40, 31, &[(1, 0), (0, 1), (1, 1), (2, 0)]);
        let n = runs.particles;
        assert!(runs.blocks.len() >= 3, "the test spans several blocks");
        let mut two = runs.two_passes();
        let blocks = two.blocks();
        (0..blocks.len()).for_each(|b| blocks.fill(b, &p, &v));
        let past = n + 40;
        let ranges = [
            0..past,
            5..1000,
            1000..2048,
            1500..2600,
            2040..past,
            n - 3..past,
        ];
        for range in ranges {
            let len = range.len();
            let mut added: Components = std::array::from_fn(|_| vec![0.0; len]);
            two.add_to(range.clone(), added.each_mut().map(|a| &mut a[..]));
            let mut written: Components = std::array::from_fn(|_| vec![f32::NAN; len]);
            two.write_to(range.clone(), written.each_mut().map(|a| &mut a[..]));
            assert!(written == added, "{range:?}");
            assert!(added[0].iter().any(|&f| f != 0.0), "{range:?}: no forces");
        }
    }

    /// Block products against the plain per-spring sum, on one thread and on two.
    #[test]
    fn block_products_are_each_springs_block_times_the_other_end() {
        let (w, h) = (60usize, 50usize);
        let n = w * h;
        let mut rnd = crate::test_rng::uniform(99);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for p in 0..n {
            for (di, dj) in [(1, 0), (0, 1), (1, 1), (0, 2)] {
                let (i, j) = (p % w + di, p / w + dj);
                if i < w && j < h {
                    // Ends in either order.
                    let q = (j * w + i) as u32;
                    let (x, y) = if rnd() < 0.5 {
                        (p as u32, q)
                    } else {
                        (q, p as u32)
                    };
                    a.push(x);
                    b.push(y);
                }
            }
        }
        // Random α, β and (not unit) n: every number of a block weighs in.
        let blocks: Vec<SpringBlock> = (0..a.len())
            .map(|_| SpringBlock {
                alpha: rnd() - 0.5,
                beta: rnd() - 0.5,
                n: Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5),
            })
            .collect();
        let u: Vec<Vec3> = (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect();
        let mut want = vec![Vec3::ZERO; n];
        for e in 0..a.len() {
            let (i, j) = (a[e] as usize, b[e] as usize);
            want[i] += blocks[e].matrix() * u[j];
            want[j] += blocks[e].matrix() * u[i];
        }
        let zero = vec![0.0; a.len()];
        let runs = SpringRuns::new(n, &a, &b, &zero, &zero, &zero);
        let mut s: Projectors = Default::default();
        runs.in_order(|e| blocks[e].numbers(), &mut s);
        let mut uc = Components::default();
        split(&u, &mut uc, n);
        let product = |runs: &SpringRuns| {
            let mut out = Components::default();
            crate::sim::forces::zeroed(&mut out, n);
            runs.add_block_products(&s, &uc, &mut out);
            out
        };
        let got = product(&runs);
        let scale = want.iter().map(|v| v.length()).fold(0.0, f32::max);
        for p in 0..n {
            let g = Vec3::new(got[0][p], got[1][p], got[2][p]);
            assert!((g - want[p]).length() <= 1e-5 * scale, "particle {p}");
        }
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let parallel = runs.clone().parallel_from(1);
            assert!(
                pool.install(|| product(&parallel)) == got,
                "{threads} threads"
            );
        }
    }

    /// A plain grid's stencil: the ends of its rows are filled, so each offset is one run
    /// per block, not one per row; the fillers add nothing.
    #[test]
    fn row_ends_are_filled_so_each_offset_is_one_run_per_block() {
        let (w, h) = (50usize, 60usize);
        let n = w * h;
        let offsets = [(1, 0), (0, 1), (1, 1), (2, 0)];
        let (a, b) = stencil(w, h, &offsets);
        let pos: Vec<Vec3> = (0..n)
            .map(|p| Vec3::new((p % w) as f32, (p / w) as f32, (p % 7) as f32) * 0.01)
            .collect();
        let vel: Vec<Vec3> = (0..n).map(|p| Vec3::splat((p % 5) as f32 - 2.0)).collect();
        let rest = vec![0.008; a.len()];
        let (k, c) = (vec![300.0; a.len()], vec![0.02; a.len()]);
        let runs = SpringRuns::new(n, &a, &b, &rest, &k, &c);
        assert!(
            runs.run_count() <= offsets.len() * runs.blocks.len(),
            "{} runs for {} offsets in {} blocks",
            runs.run_count(),
            offsets.len(),
            runs.blocks.len()
        );
        let want = reference(&a, &b, &rest, &k, &c, &pos, &vel);
        let mut got = vec![Vec3::ZERO; n];
        runs.add_forces(&pos, &vel, &mut got);
        let scale = want.iter().map(|f| f.length()).fold(0.0, f32::max);
        for p in 0..n {
            assert!((got[p] - want[p]).length() <= 1e-5 * scale, "particle {p}");
        }
    }
}
