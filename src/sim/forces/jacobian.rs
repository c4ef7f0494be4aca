//! Force derivatives assembled into the implicit-Euler system
//! `A = M − h·∂f/∂v − h²·∂f/∂x`, stored as 3×3 blocks: one per spring and one per particle.

use crate::cloth::{ClothModel, Matrix, Real, Springs, Vector};

use std::ops::Range;

use crate::sim::kernels::{Blocks, Components, SystemSums, blocks_times, split, zeroed};

use super::system_springs::{SpringBlock, SystemSprings};

/// The entries of a block (column-major) on its diagonal: `xx, yy, zz`.
const ON_DIAGONAL: [usize; 3] = [0, 4, 8];
/// The entries below a block's diagonal (`xy, xz, yz`, as [`SystemSums::off_diagonal`]
/// holds them), each with its mirror above.
const BELOW_DIAGONAL: [(usize, usize); 3] = [(1, 3), (2, 6), (5, 7)];

/// Which derivative a force term reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JacobianMode {
    /// The true derivative of the forces.
    Exact,
    /// The symmetric positive semi-definite approximation implicit solvers use (see
    /// [`super::SpringForce::blocks`]).
    Definite,
}

/// `A = M − h·∂f/∂v − h²·∂f/∂x` for one step of length `h`, plus `∂f/∂x·v` for the
/// right-hand side. With [`JacobianMode::Definite`] blocks it is symmetric positive definite.
///
/// A spring `e = (a, b)` with blocks `K_x`, `K_v` contributes `S_e = h·K_v + h²·K_x`: `+S_e`
/// to the diagonal blocks of `a` and `b` and `−S_e` to the off-diagonal blocks `(a, b)`,
/// `(b, a)`. Per-particle terms (air damping) add to the diagonal only. The spring terms
/// say which springs and how strong ([`SystemMatrix::add_springs`]); their blocks are
/// computed together when the matrix is finished ([`SystemMatrix::finish`]), in the
/// springs' runs ([`SpringRuns::add_system_blocks`]), so that assembling them and
/// multiplying by them are the vector loops and threads of the spring forces.
///
/// [`SpringRuns::add_system_blocks`]: crate::sim::kernels::SpringRuns::add_system_blocks
#[derive(Clone, Debug)]
pub struct SystemMatrix<R: Real = f32> {
    /// Step length, seconds.
    pub h: R,
    /// The springs' blocks.
    springs: SystemSprings<R>,
    /// Diagonal block per particle, kg, one array per entry (column-major: entry `3c + r`
    /// is row `r` of column `c`).
    diag: Blocks<R>,
    /// `(∂f/∂x)·v` at the state the matrix was built at, N/s, one array per component.
    dfdx_v: Components<R>,
    /// The state one array per component.
    pos: Components<R>,
    vel: Components<R>,
}

impl<R: Real> Default for SystemMatrix<R> {
    fn default() -> Self {
        Self {
            h: R::ZERO,
            springs: SystemSprings::default(),
            diag: Default::default(),
            dfdx_v: Default::default(),
            pos: Default::default(),
            vel: Default::default(),
        }
    }
}

impl<R: Real> SystemMatrix<R> {
    /// Starts a new matrix `M` for a step of `h` seconds (no allocation once sized); the
    /// terms add to it, and [`SystemMatrix::finish`] completes it.
    pub fn begin(&mut self, model: &ClothModel, h: R) {
        let n = model.particle_count();
        self.h = h;
        self.springs.begin();
        for (entry, d) in self.diag.iter_mut().enumerate() {
            d.clear();
            if ON_DIAGONAL.contains(&entry) {
                d.extend(model.mass.iter().map(|&m| R::of_f32(m)));
            } else {
                d.resize(n, R::ZERO);
            }
        }
        zeroed(&mut self.dfdx_v, n);
    }

    /// Particle `p`'s diagonal block.
    pub fn diag_block(&self, p: usize) -> R::M3 {
        let d = &self.diag;
        let col = |c: usize| R::V3::new(d[3 * c][p], d[3 * c + 1][p], d[3 * c + 2][p]);
        R::M3::from_cols(col(0), col(1), col(2))
    }

    /// How many particles the matrix is for.
    pub fn particles(&self) -> usize {
        self.diag[0].len()
    }

    /// `(∂f/∂x)·v` at particle `p`, N/s.
    pub fn dfdx_v(&self, p: usize) -> R::V3 {
        let d = &self.dfdx_v;
        R::V3::new(d[0][p], d[1][p], d[2][p])
    }

    /// Adds the springs `range` of `springs`, with stiffness `k` and damping `c` per
    /// spring of the range: at [`SystemMatrix::finish`], each spring's block
    /// `S_e = α·I + β·n nᵀ` with `α = h²·k·s`, `β = h·c + h²·k(1 − s)`,
    /// `s = max(0, 1 − l₀/|d|)`, and `K_x·(v_b − v_a) = k·s·w + k(1 − s)(n·w)·n` (see
    /// [`SpringForce::add_to_system`](super::SpringForce::add_to_system)). Each spring
    /// once a matrix.
    pub fn add_springs(
        &mut self,
        springs: &Springs,
        range: Range<usize>,
        strengths: (&[f32], &[f32]),
    ) {
        self.springs.add(springs.len(), range, strengths);
    }

    /// Completes the matrix at positions `pos` and velocities `vel`: the blocks of the
    /// springs added, and their sums on the diagonal and in `(∂f/∂x)·v`.
    pub fn finish(&mut self, springs: &Springs, pos: &[R::V3], vel: &[R::V3]) {
        let n = self.particles().min(pos.len()).min(vel.len());
        split(pos, &mut self.pos, n);
        split(vel, &mut self.vel, n);
        // The sums are added where they belong: the diagonal entries, the entries below it
        // (copied above it after), and `(∂f/∂x)·v`.
        let d = &mut self.diag;
        let take = std::mem::take::<Vec<R>>;
        let mut sums = SystemSums {
            diagonal: ON_DIAGONAL.map(|e| take(&mut d[e])),
            off_diagonal: BELOW_DIAGONAL.map(|(e, _)| take(&mut d[e])),
            dfdx_v: std::mem::take(&mut self.dfdx_v),
        };
        let state = (&self.pos, &self.vel, self.h);
        self.springs.assemble(springs, n, state, &mut sums);
        let SystemSums {
            diagonal,
            off_diagonal,
            dfdx_v,
        } = sums;
        for (e, sum) in ON_DIAGONAL.into_iter().zip(diagonal) {
            d[e] = sum;
        }
        for ((below, above), sum) in BELOW_DIAGONAL.into_iter().zip(off_diagonal) {
            d[above].clone_from(&sum);
            d[below] = sum;
        }
        self.dfdx_v = dfdx_v;
    }

    /// Adds a per-particle `∂f_p/∂v_p = d·I` (N·s/m).
    pub fn add_dv_diagonal(&mut self, p: usize, d: R) {
        for e in ON_DIAGONAL {
            self.diag[e][p] -= self.h * d;
        }
    }

    /// Each spring's block `S_e`, indexed as the model's `springs` springs (zero for a
    /// spring no term added).
    pub fn spring_blocks(&self, springs: usize) -> Vec<SpringBlock<R>> {
        self.springs.by_spring(springs)
    }

    /// `out = A·u`, gathered per particle over `model.adjacency`, one block at a time
    /// (for tests: the solver multiplies with [`SystemMatrix::add_coupling`] and the
    /// [`SystemMatrix::diagonal`] blocks, which [`SystemMatrix::apply_components`] puts
    /// together).
    pub fn apply(&self, model: &ClothModel, u: &[R::V3], out: &mut [R::V3]) {
        let adj = &model.adjacency;
        let spring = self.spring_blocks(model.springs.len());
        for (p, o) in out.iter_mut().enumerate() {
            let mut sum = self.diag_block(p) * u[p];
            for slot in adj.range(p) {
                sum -= spring[adj.spring[slot] as usize].times(u[adj.other[slot] as usize]);
            }
            *o = sum;
        }
    }

    /// `out = A·u` with `u` and `out` stored one array per component (`out` as long as
    /// `u`): the springs' products in their runs, with the threads of the spring forces,
    /// then the diagonal blocks' — the two halves the solver takes in its own passes. The
    /// same as [`SystemMatrix::apply`] up to rounding.
    pub fn apply_components(&self, u: &Components<R>, out: &mut Components<R>) {
        let n = u[0].len().min(self.particles());
        for o in out.iter_mut() {
            o[..n].fill(R::ZERO);
        }
        self.add_coupling(u, out);
        blocks_times(&self.diag, u, out, |diagonal, sums| diagonal - sums);
    }

    /// Adds `Σ_e S_e·u_other` at both ends of every spring to `out`: the product's
    /// off-diagonal part, negated, so that `A·u` is [`SystemMatrix::diagonal`]`·u` less
    /// these sums (for a solver that takes the diagonal part in its own loops).
    pub fn add_coupling(&self, u: &Components<R>, out: &mut Components<R>) {
        self.springs.add_products(u, out);
    }

    /// The diagonal blocks, one array per entry.
    pub fn diagonal(&self) -> &Blocks<R> {
        &self.diag
    }

    /// The whole matrix, dense and row-major (`3n × 3n`), for tests on small systems.
    pub fn dense(&self, springs: &Springs) -> Vec<Vec<f64>> {
        let n = self.particles();
        let mut m = vec![vec![0.0f64; 3 * n]; 3 * n];
        let mut put = |i: usize, j: usize, block: R::M3, sign: f64| {
            for r in 0..3 {
                for c in 0..3 {
                    m[3 * i + r][3 * j + c] += sign * block.col(c).to_array()[r].to_f64();
                }
            }
        };
        for p in 0..n {
            put(p, p, self.diag_block(p), 1.0);
        }
        for (e, s) in self.spring_blocks(springs.len()).iter().enumerate() {
            let (a, b) = (springs.a[e] as usize, springs.b[e] as usize);
            put(a, b, s.matrix(), -1.0);
            put(b, a, s.matrix(), -1.0);
        }
        m
    }
}
