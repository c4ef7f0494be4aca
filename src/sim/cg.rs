//! Preconditioned conjugate gradients on the implicit system, with pinned particles
//! filtered out of the solve (their unknowns stay zero) and a block-Jacobi preconditioner.

use glam::{Mat3, Vec3};

use crate::cloth::ClothModel;

use super::forces::{SystemMatrix, SystemProduct};
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

/// Scratch vectors of a solve, kept between steps (no allocation once sized).
#[derive(Clone, Debug, Default)]
pub struct ConjugateGradient {
    r: Vec<Vec3>,
    z: Vec<Vec3>,
    p: Vec<Vec3>,
    q: Vec<Vec3>,
    precond: Vec<Mat3>,
    product: SystemProduct,
}

fn dot(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y) as f64).sum()
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
        let free = |i: usize| model.inv_mass[i] > 0.0;
        if x.len() != n {
            x.clear();
            x.resize(n, Vec3::ZERO);
        }
        for (i, xi) in x.iter_mut().enumerate() {
            if !free(i) || !xi.is_finite() {
                *xi = Vec3::ZERO;
            }
        }
        self.precond.clear();
        self.precond.extend((0..n).map(|i| {
            if free(i) {
                sys.diag[i].inverse()
            } else {
                Mat3::ZERO
            }
        }));
        let b_norm = (0..n)
            .filter(|&i| free(i))
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
        // r = b − A·x for the starting guess.
        self.q.resize(n, Vec3::ZERO);
        self.product.load(model, sys);
        self.product.apply(sys, x, &mut self.q);
        self.r.clear();
        self.r.extend((0..n).map(|i| {
            if free(i) {
                b[i] - self.q[i]
            } else {
                Vec3::ZERO
            }
        }));
        self.z.clear();
        self.z
            .extend(self.precond.iter().zip(&self.r).map(|(m, r)| *m * *r));
        self.p.clone_from(&self.z);
        let mut rz = dot(&self.r, &self.z);
        let target = tolerance as f64 * b_norm;
        let mut residual = dot(&self.r, &self.r).sqrt();
        let mut iterations = 0;
        while iterations < max_iterations && residual > target {
            iterations += 1;
            self.product.apply(sys, &self.p, &mut self.q);
            for (i, q) in self.q.iter_mut().enumerate() {
                if !free(i) {
                    *q = Vec3::ZERO;
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
            for (x, p) in x.iter_mut().zip(&self.p) {
                *x += alpha * *p;
            }
            let residuals = self.r.iter_mut().zip(self.z.iter_mut());
            for (((r, z), q), m) in residuals.zip(&self.q).zip(&self.precond) {
                *r -= alpha * *q;
                *z = *m * *r;
            }
            residual = dot(&self.r, &self.r).sqrt();
            let rz_next = dot(&self.r, &self.z);
            let beta = (rz_next / rz) as f32;
            rz = rz_next;
            for (p, z) in self.p.iter_mut().zip(&self.z) {
                *p = *z + beta * *p;
            }
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
