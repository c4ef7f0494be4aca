//! Force derivatives assembled into the implicit-Euler system
//! `A = M − h·∂f/∂v − h²·∂f/∂x`, stored as 3×3 blocks: one per spring and one per particle.

use crate::cloth::{ClothModel, Matrix, Real, Springs, Vector};

use crate::sim::kernels::{Blocks, Components, Projectors, SpringRuns, blocks_times, split_blocks};

/// Which derivative a force term reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JacobianMode {
    /// The true derivative of the forces.
    Exact,
    /// The symmetric positive semi-definite approximation implicit solvers use (see
    /// [`super::SpringForce::blocks`]).
    Definite,
}

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
    /// spring.
    pub fn numbers(&self) -> [R; 5] {
        let n = self.n;
        [self.alpha, self.beta, n.x(), n.y(), n.z()]
    }

    /// `S·u`.
    pub fn times(&self, u: R::V3) -> R::V3 {
        u * self.alpha + self.n * (self.beta * self.n.dot(u))
    }
}

/// `A = M − h·∂f/∂v − h²·∂f/∂x` for one step of length `h`, plus `∂f/∂x·v` for the
/// right-hand side. With [`JacobianMode::Definite`] blocks it is symmetric positive definite.
///
/// A spring `e = (a, b)` with blocks `K_x`, `K_v` contributes `S_e = h·K_v + h²·K_x`: `+S_e`
/// to the diagonal blocks of `a` and `b` and `−S_e` to the off-diagonal blocks `(a, b)`,
/// `(b, a)`. Per-particle terms (air damping) add to the diagonal only.
#[derive(Clone, Debug)]
pub struct SystemMatrix<R: Real = f32> {
    /// Step length, seconds.
    pub h: R,
    /// `S_e` per spring.
    pub spring: Vec<SpringBlock<R>>,
    /// Diagonal block per particle, kg.
    pub diag: Vec<R::M3>,
    /// `(∂f/∂x)·v` at the state the matrix was built at, N/s.
    pub dfdx_v: Vec<R::V3>,
}

impl<R: Real> Default for SystemMatrix<R> {
    fn default() -> Self {
        Self {
            h: R::ZERO,
            spring: Vec::new(),
            diag: Vec::new(),
            dfdx_v: Vec::new(),
        }
    }
}

impl<R: Real> SystemMatrix<R> {
    /// Starts a new matrix `M` for a step of `h` seconds (no allocation once sized).
    pub fn begin(&mut self, model: &ClothModel, h: R) {
        let (n, e) = (model.particle_count(), model.springs.len());
        self.h = h;
        self.spring.clear();
        self.spring.resize(e, SpringBlock::default());
        self.diag.clear();
        self.diag.extend(
            model
                .mass
                .iter()
                .map(|&m| R::M3::from_diagonal(R::V3::splat(R::of_f32(m)))),
        );
        self.dfdx_v.clear();
        self.dfdx_v.resize(n, R::V3::ZERO);
    }

    /// Sets spring `e`'s system block `S_e = h·K_v + h²·K_x` (one force term per spring) and
    /// adds `K_x·(v_b − v_a)`.
    #[inline]
    pub fn add_spring_block(
        &mut self,
        springs: &Springs,
        e: usize,
        s: SpringBlock<R>,
        dfdx_w: R::V3,
    ) {
        let (a, b) = (springs.a[e] as usize, springs.b[e] as usize);
        debug_assert_eq!(
            self.spring[e],
            SpringBlock::default(),
            "spring {e} set twice"
        );
        self.spring[e] = s;
        let m = s.matrix();
        self.diag[a] += m;
        self.diag[b] += m;
        self.dfdx_v[a] += dfdx_w;
        self.dfdx_v[b] -= dfdx_w;
    }

    /// Adds a per-particle `∂f_p/∂v_p = d·I` (N·s/m).
    pub fn add_dv_diagonal(&mut self, p: usize, d: R) {
        self.diag[p] -= R::M3::from_diagonal(R::V3::splat(self.h * d));
    }

    /// `out = A·u`, gathered per particle over `model.adjacency`.
    pub fn apply(&self, model: &ClothModel, u: &[R::V3], out: &mut [R::V3]) {
        let adj = &model.adjacency;
        for (p, o) in out.iter_mut().enumerate() {
            let mut sum = self.diag[p] * u[p];
            for slot in adj.range(p) {
                sum -= self.spring[adj.spring[slot] as usize].times(u[adj.other[slot] as usize]);
            }
            *o = sum;
        }
    }

    /// The whole matrix, dense and row-major (`3n × 3n`), for tests on small systems.
    pub fn dense(&self, springs: &Springs) -> Vec<Vec<f64>> {
        let n = self.diag.len();
        let mut m = vec![vec![0.0f64; 3 * n]; 3 * n];
        let mut put = |i: usize, j: usize, block: R::M3, sign: f64| {
            for r in 0..3 {
                for c in 0..3 {
                    m[3 * i + r][3 * j + c] += sign * block.col(c).to_array()[r].to_f64();
                }
            }
        };
        for (p, &d) in self.diag.iter().enumerate() {
            put(p, p, d, 1.0);
        }
        for (e, s) in self.spring.iter().enumerate() {
            let (a, b) = (springs.a[e] as usize, springs.b[e] as usize);
            put(a, b, s.matrix(), -1.0);
            put(b, a, s.matrix(), -1.0);
        }
        m
    }
}

/// [`SystemMatrix::apply`] for repeated products with one matrix (a linear solve's): each
/// spring's `α, β, n` copied once into the order of the springs' runs, one array per
/// number, so each product is the vector loops and threads of the spring forces rather
/// than a 3×3 product per neighbour. The runs are kept while the model's springs stay the
/// same.
#[derive(Clone, Debug)]
pub struct SystemProduct<R: Real = f32> {
    /// The springs the runs were made for.
    ends: (Vec<u32>, Vec<u32>),
    runs: Option<SpringRuns<R>>,
    blocks: Projectors<R>,
    /// The particles' diagonal blocks, one array per entry (column-major).
    diag: Blocks<R>,
}

impl<R: Real> Default for SystemProduct<R> {
    fn default() -> Self {
        Self {
            ends: Default::default(),
            runs: None,
            blocks: Default::default(),
            diag: Default::default(),
        }
    }
}

impl<R: Real> SystemProduct<R> {
    /// Takes `sys`'s spring blocks (call again when the matrix changes).
    pub fn load(&mut self, model: &ClothModel, sys: &SystemMatrix<R>) {
        let springs = &model.springs;
        if self.runs.is_none() || self.ends.0 != springs.a || self.ends.1 != springs.b {
            self.ends = (springs.a.clone(), springs.b.clone());
            let none = vec![R::ZERO; springs.len()];
            let particles = model.particle_count();
            self.runs = Some(SpringRuns::new(
                particles, &springs.a, &springs.b, &none, &none, &none,
            ));
        }
        if let Some(runs) = &self.runs {
            runs.in_order(|e| sys.spring[e].numbers(), &mut self.blocks);
        }
        split_blocks(sys.diag.iter().copied(), &mut self.diag);
    }

    /// `out = A·u` with the matrix last [loaded](SystemProduct::load), `u` and `out` stored
    /// one array per component (`out` as long as `u`): the same as [`SystemMatrix::apply`] up
    /// to rounding.
    pub fn apply_components(&self, u: &Components<R>, out: &mut Components<R>) {
        let n = u[0].len().min(self.diag[0].len());
        for o in out.iter_mut() {
            o[..n].fill(R::ZERO);
        }
        if let Some(runs) = &self.runs {
            runs.add_block_products(&self.blocks, u, out);
        }
        blocks_times(&self.diag, u, out, |diagonal, sums| diagonal - sums);
    }
}
