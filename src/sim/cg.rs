//! Preconditioned conjugate gradients on the implicit system, with pinned particles
//! filtered out of the solve (their unknowns stay zero) and a block-Jacobi preconditioner.

use glam::{Mat3, Vec3};

use crate::cloth::ClothModel;

use super::forces::{
    Blocks, Components, SystemMatrix, SystemProduct, blocks_times, split, split_blocks, zeroed,
};
use super::integrator::StepError;

/// How a solve ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgOutcome {
    pub iterations: u32,
    /// `‖b − A·x‖ / ‖b‖` at the end (0 for `b = 0`).
    pub residual: f32,
    /// Whether the residual reached the tolerance within the iteration cap.
    pub converged: bool,
}

/// Scratch vectors of a solve, kept between steps (no allocation once sized). The vectors
/// are stored one array per component, so every update is a vector loop.
#[derive(Clone, Debug, Default)]
pub struct ConjugateGradient {
    x: Components,
    r: Components,
    z: Components,
    p: Components,
    q: Components,
    /// The preconditioner's 3×3 blocks, one array per entry (column-major).
    precond: Blocks,
    free: Vec<bool>,
    product: SystemProduct,
}

/// `Σ a_i·b_i`, each particle's dot product in f32 summed in f64.
fn dot(a: &Components, b: &Components) -> f64 {
    let [ax, ay, az] = a;
    let [bx, by, bz] = b;
    let n = ax.len().min(bx.len());
    let (ay, az, by, bz) = (&ay[..n], &az[..n], &by[..n], &bz[..n]);
    (0..n)
        .map(|i| (ax[i] * bx[i] + ay[i] * by[i] + az[i] * bz[i]) as f64)
        .sum()
}

impl ConjugateGradient {
    /// Solves `A·x = b` for the free particles (inverse mass > 0); pinned rows are held
    /// at zero. `x` is the starting guess when it has one entry per particle (a warm start
    /// from the last step's solution), else zero. Stops when `‖r‖ ≤ tolerance·‖b‖` or after
    /// `max_iterations`.
    ///
    /// # Errors
    /// [`StepError::Breakdown`] when a search direction has non-positive curvature (the
    /// matrix is not positive definite), [`StepError::NonFinite`] on NaN or infinity.
    pub fn solve(
        &mut self,
        model: &ClothModel,
        sys: &SystemMatrix,
        b: &[Vec3],
        x: &mut Vec<Vec3>,
        tolerance: f32,
        max_iterations: u32,
    ) -> Result<CgOutcome, StepError> {
        let n = b.len();
        self.free.clear();
        self.free.extend((0..n).map(|i| model.inv_mass[i] > 0.0));
        let free = &self.free;
        if x.len() != n {
            x.clear();
            x.resize(n, Vec3::ZERO);
        }
        for (i, xi) in x.iter_mut().enumerate() {
            if !free[i] || !xi.is_finite() {
                *xi = Vec3::ZERO;
            }
        }
        let b_norm = (0..n)
            .filter(|&i| free[i])
            .map(|i| b[i].length_squared() as f64)
            .sum::<f64>()
            .sqrt();
        if b_norm == 0.0 {
            x.iter_mut().for_each(|xi| *xi = Vec3::ZERO);
            return Ok(CgOutcome {
                iterations: 0,
                residual: 0.0,
                converged: true,
            });
        }
        let inverse = |(d, &free): (&Mat3, &bool)| if free { d.inverse() } else { Mat3::ZERO };
        split_blocks(sys.diag.iter().zip(free).map(inverse), &mut self.precond);
        for v in [&mut self.r, &mut self.z, &mut self.p, &mut self.q] {
            zeroed(v, n);
        }
        split(x, &mut self.x, n);
        // r = b − A·x for the starting guess.
        self.product.load(model, sys);
        self.product.apply_components(&self.x, &mut self.q);
        for (c, r) in self.r.iter_mut().enumerate() {
            for (i, r) in r.iter_mut().enumerate() {
                *r = if free[i] { b[i][c] - self.q[c][i] } else { 0.0 };
            }
        }
        blocks_times(&self.precond, &self.r, &mut self.z, |z, _| z);
        self.p.clone_from(&self.z);
        let mut rz = dot(&self.r, &self.z);
        let target = tolerance as f64 * b_norm;
        let mut residual = dot(&self.r, &self.r).sqrt();
        let mut iterations = 0;
        while iterations < max_iterations && residual > target {
            iterations += 1;
            self.product.apply_components(&self.p, &mut self.q);
            for q in &mut self.q {
                for (q, &free) in q.iter_mut().zip(free) {
                    *q = if free { *q } else { 0.0 };
                }
            }
            let curvature = dot(&self.p, &self.q);
            if !curvature.is_finite() {
                return Err(StepError::NonFinite { iterations });
            }
            if curvature <= 0.0 {
                return Err(StepError::Breakdown { iterations });
            }
            let alpha = (rz / curvature) as f32;
            for (x, p) in self.x.iter_mut().zip(&self.p) {
                x.iter_mut().zip(p).for_each(|(x, &p)| *x += alpha * p);
            }
            for (r, q) in self.r.iter_mut().zip(&self.q) {
                r.iter_mut().zip(q).for_each(|(r, &q)| *r -= alpha * q);
            }
            blocks_times(&self.precond, &self.r, &mut self.z, |z, _| z);
            residual = dot(&self.r, &self.r).sqrt();
            let rz_next = dot(&self.r, &self.z);
            let beta = (rz_next / rz) as f32;
            rz = rz_next;
            for (p, z) in self.p.iter_mut().zip(&self.z) {
                p.iter_mut().zip(z).for_each(|(p, &z)| *p = z + beta * *p);
            }
        }
        let [x0, x1, x2] = &self.x;
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = Vec3::new(x0[i], x1[i], x2[i]);
        }
        if !residual.is_finite() {
            return Err(StepError::NonFinite { iterations });
        }
        Ok(CgOutcome {
            iterations,
            residual: (residual / b_norm) as f32,
            converged: residual <= target,
        })
    }
}
