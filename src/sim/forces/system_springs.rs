//! The springs' blocks of the implicit system: the spring terms say which springs and how
//! strong; the blocks of all of them are computed together, in one set of runs.

use std::ops::Range;

use crate::cloth::{Matrix, Real, Springs, Vector};
use crate::sim::kernels::{Components, Projectors, SpringRuns, SystemSums};

/// A spring's block in the system, `S = α·I + β·n nᵀ` (kg): the form every definite spring
/// Jacobian takes (see [`super::SpringForce::add_to_system`]). Five numbers instead of
/// nine, and half the arithmetic in a product.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpringBlock<R: Real = f32> {
    pub alpha: R,
    pub beta: R,
    pub n: R::V3,
}

impl<R: Real> SpringBlock<R> {
    /// The block as a matrix.
    pub fn matrix(&self) -> R::M3 {
        let bn = self.n * self.beta;
        let n = self.n;
        R::M3::IDENTITY * self.alpha + R::M3::from_cols(bn * n.x(), bn * n.y(), bn * n.z())
    }

    /// `[α, β, n.x, n.y, n.z]`: the numbers `SpringRuns::add_block_products` reads per
    /// spring (tests put blocks of their own in run order with them).
    #[cfg(test)]
    pub fn numbers(&self) -> [R; 5] {
        let n = self.n;
        [self.alpha, self.beta, n.x(), n.y(), n.z()]
    }

    /// `S·u`.
    pub fn times(&self, u: R::V3) -> R::V3 {
        u * self.alpha + self.n * (self.beta * self.n.dot(u))
    }
}

/// The springs the terms added to one matrix, and their blocks `S_e = α·I + β·n nᵀ` in the
/// order of the runs made over them (kept between steps: the runs are made again only
/// when the springs change).
#[derive(Clone, Debug)]
pub(super) struct SystemSprings<R: Real> {
    /// The ranges of the model's springs added since the matrix began, in order, and
    /// their stiffness and damping, one after the other.
    ranges: Vec<Range<usize>>,
    k: Vec<f32>,
    c: Vec<f32>,
    /// The runs and what they were made for: those ranges, the springs' ends there and
    /// the strengths last put into them.
    runs: Option<SpringRuns<R>>,
    made_for: Vec<Range<usize>>,
    ends: (Vec<u32>, Vec<u32>),
    strengths: (Vec<f32>, Vec<f32>),
    /// `[α, β, n.x, n.y, n.z]` per place in run order.
    blocks: Projectors<R>,
    /// Whether the blocks are this matrix's (computed since it began).
    live: bool,
}

impl<R: Real> Default for SystemSprings<R> {
    fn default() -> Self {
        Self {
            ranges: Vec::new(),
            k: Vec::new(),
            c: Vec::new(),
            runs: None,
            made_for: Vec::new(),
            ends: Default::default(),
            strengths: Default::default(),
            blocks: Default::default(),
            live: false,
        }
    }
}

impl<R: Real> SystemSprings<R> {
    /// Forgets the springs added (a new matrix begins).
    pub(super) fn begin(&mut self) {
        self.ranges.clear();
        self.k.clear();
        self.c.clear();
        self.live = false;
    }

    /// Adds the springs `range` (of `count` springs) with stiffness `k` and damping `c`
    /// per spring of the range.
    pub(super) fn add(&mut self, count: usize, range: Range<usize>, (k, c): (&[f32], &[f32])) {
        let end = range.end.min(count);
        let range = range.start.min(end)..end;
        let len = range.len().min(k.len()).min(c.len());
        self.ranges.push(range.start..range.start + len);
        self.k.extend_from_slice(&k[..len]);
        self.c.extend_from_slice(&c[..len]);
    }

    /// Computes the blocks of the springs added at positions `p` and velocities `v` of
    /// `particles` particles, for a step of `h` seconds, adding their sums to `sums` (see
    /// [`SpringRuns::add_system_blocks`]).
    pub(super) fn assemble(
        &mut self,
        springs: &Springs,
        particles: usize,
        (p, v, h): (&Components<R>, &Components<R>, R),
        sums: &mut SystemSums<R>,
    ) {
        if self.ranges.is_empty() {
            return;
        }
        let mut runs = match self.runs.take() {
            Some(runs) if self.made_for_these(springs) && runs.covers(particles) => runs,
            _ => self.make_runs(springs, particles),
        };
        // Compared bit for bit (one `memcmp`, where comparing as numbers is a branch each).
        let bits = bytemuck::cast_slice::<f32, u8>;
        if (bits(&self.strengths.0), bits(&self.strengths.1)) != (bits(&self.k), bits(&self.c)) {
            let wide = |v: &[f32]| v.iter().map(|&x| R::of_f32(x)).collect::<Vec<_>>();
            runs.set_strengths(&wide(&self.k), &wide(&self.c));
            self.strengths = (self.k.clone(), self.c.clone());
        }
        runs.add_system_blocks(p, v, h, &mut self.blocks, sums);
        self.runs = Some(runs);
        self.live = true;
    }

    /// Whether the runs were made for the ranges added, with the ends the springs have
    /// there now.
    fn made_for_these(&self, springs: &Springs) -> bool {
        if self.made_for != self.ranges {
            return false;
        }
        let mut at = 0;
        self.ranges.iter().all(|r| {
            let there = at..at + r.len();
            at += r.len();
            self.ends.0[there.clone()] == springs.a[r.clone()]
                && self.ends.1[there] == springs.b[r.clone()]
        })
    }

    /// Runs over the springs of the ranges added, one after the other.
    fn make_runs(&mut self, springs: &Springs, particles: usize) -> SpringRuns<R> {
        let pick = |v: &[u32]| -> Vec<u32> {
            (self.ranges.iter())
                .flat_map(|r| v[r.clone()].iter().copied())
                .collect()
        };
        self.ends = (pick(&springs.a), pick(&springs.b));
        self.made_for.clone_from(&self.ranges);
        let rest: Vec<R> = (self.ranges.iter())
            .flat_map(|r| springs.rest[r.clone()].iter().map(|&l| R::of_f32(l)))
            .collect();
        let none = vec![R::ZERO; rest.len()];
        self.strengths = (vec![0.0; rest.len()], vec![0.0; rest.len()]);
        SpringRuns::new(particles, &self.ends.0, &self.ends.1, &rest, &none, &none)
    }

    /// Adds `Σ_e S_e·u_other` at both ends of every spring to `out` (the off-diagonal part
    /// of a product with the matrix, negated).
    pub(super) fn add_products(&self, u: &Components<R>, out: &mut Components<R>) {
        if let (true, Some(runs)) = (self.live, &self.runs) {
            runs.add_block_products(&self.blocks, u, out);
        }
    }

    /// Each spring's block, indexed as the model's `count` springs (zero for a spring no
    /// term added).
    pub(super) fn by_spring(&self, count: usize) -> Vec<SpringBlock<R>> {
        let mut out = vec![SpringBlock::default(); count];
        let (true, Some(runs)) = (self.live, &self.runs) else {
            return out;
        };
        // The model's index of each spring the runs were made over.
        let index: Vec<usize> = self.ranges.iter().flat_map(|r| r.clone()).collect();
        for (place, i) in runs.places() {
            let [alpha, beta, x, y, z] = self.blocks.each_ref().map(|b| b[place]);
            out[index[i]] = SpringBlock {
                alpha,
                beta,
                n: R::V3::new(x, y, z),
            };
        }
        out
    }
}
