//! Preconditioned conjugate gradients on the implicit system, with pinned particles
//! filtered out of the solve (their unknowns stay zero) and a block-Jacobi preconditioner.

use crate::cloth::{ClothModel, Matrix, Real, Vector};

use super::forces::SystemMatrix;
use super::integrator::StepError;
use super::kernels::{Blocks, Components, blocks_times, split, split_blocks, zeroed};

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
pub struct ConjugateGradient<R: Real = f32> {
    x: Components<R>,
    r: Components<R>,
    z: Components<R>,
    p: Components<R>,
    q: Components<R>,
    /// The preconditioner's 3×3 blocks, one array per entry (column-major).
    precond: Blocks<R>,
    free: Vec<bool>,
}

/// `Σ a_i·b_i`: eight f32 lanes sum a block of 64 particles (eight each, side by side in
/// the vector units), and the blocks' sums add up in f64. (One f64 running sum was a chain
/// of dependent additions, an eighth of an implicit step's time.)
fn dot<R: Real>(a: &Components<R>, b: &Components<R>) -> f64 {
    const LANES: usize = 8;
    const BLOCK: usize = 8 * LANES;
    let zero = [R::ZERO; LANES];
    let n = a[0].len().min(b[0].len());
    let lanes_of = |v: &[R]| -> [R; LANES] { v.try_into().unwrap_or(zero) };
    let mut total = 0.0f64;
    for start in (0..n).step_by(BLOCK) {
        let end = (start + BLOCK).min(n);
        let whole = start + (end - start) / LANES * LANES;
        let mut sum = zero;
        for k in (start..whole).step_by(LANES) {
            for c in 0..3 {
                let (u, v) = (lanes_of(&a[c][k..k + LANES]), lanes_of(&b[c][k..k + LANES]));
                for l in 0..LANES {
                    sum[l] += u[l] * v[l];
                }
            }
        }
        for i in whole..end {
            sum[0] += a[0][i] * b[0][i] + a[1][i] * b[1][i] + a[2][i] * b[2][i];
        }
        total += sum.iter().map(|s| s.to_f64()).sum::<f64>();
    }
    total
}

impl<R: Real> ConjugateGradient<R> {
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
        sys: &SystemMatrix<R>,
        b: &[R::V3],
        x: &mut Vec<R::V3>,
        tolerance: f32,
        max_iterations: u32,
    ) -> Result<CgOutcome, StepError> {
        let n = b.len();
        self.free.clear();
        self.free.extend((0..n).map(|i| model.inv_mass[i] > 0.0));
        let free = &self.free;
        if x.len() != n {
            x.clear();
            x.resize(n, R::V3::ZERO);
        }
        for (i, xi) in x.iter_mut().enumerate() {
            if !free[i] || !xi.is_finite() {
                *xi = R::V3::ZERO;
            }
        }
        let b_norm = (0..n)
            .filter(|&i| free[i])
            .map(|i| b[i].length_squared().to_f64())
            .sum::<f64>()
            .sqrt();
        if b_norm == 0.0 {
            x.iter_mut().for_each(|xi| *xi = R::V3::ZERO);
            return Ok(CgOutcome {
                iterations: 0,
                residual: 0.0,
                converged: true,
            });
        }
        let inverse = |(p, &free)| {
            if free {
                sys.diag_block(p).inverse()
            } else {
                R::M3::ZERO
            }
        };
        split_blocks((0..n).zip(free).map(inverse), &mut self.precond);
        for v in [&mut self.r, &mut self.z, &mut self.p, &mut self.q] {
            zeroed(v, n);
        }
        split(x, &mut self.x, n);
        // r = b − A·x for the starting guess.
        sys.apply_components(&self.x, &mut self.q);
        for (c, r) in self.r.iter_mut().enumerate() {
            for (i, r) in r.iter_mut().enumerate() {
                *r = if free[i] {
                    b[i].to_array()[c] - self.q[c][i]
                } else {
                    R::ZERO
                };
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
            sys.apply_components(&self.p, &mut self.q);
            for q in &mut self.q {
                for (q, &free) in q.iter_mut().zip(free) {
                    *q = if free { *q } else { R::ZERO };
                }
            }
            let curvature = dot(&self.p, &self.q);
            if !curvature.is_finite() {
                return Err(StepError::NonFinite { iterations });
            }
            if curvature <= 0.0 {
                return Err(StepError::Breakdown { iterations });
            }
            let alpha = R::of_f64(rz / curvature);
            for (x, p) in self.x.iter_mut().zip(&self.p) {
                x.iter_mut().zip(p).for_each(|(x, &p)| *x += p * alpha);
            }
            for (r, q) in self.r.iter_mut().zip(&self.q) {
                r.iter_mut().zip(q).for_each(|(r, &q)| *r -= q * alpha);
            }
            blocks_times(&self.precond, &self.r, &mut self.z, |z, _| z);
            residual = dot(&self.r, &self.r).sqrt();
            let rz_next = dot(&self.r, &self.z);
            let beta = R::of_f64(rz_next / rz);
            rz = rz_next;
            for (p, z) in self.p.iter_mut().zip(&self.z) {
                p.iter_mut().zip(z).for_each(|(p, &z)| *p = z + *p * beta);
            }
        }
        let [x0, x1, x2] = &self.x;
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = R::V3::new(x0[i], x1[i], x2[i]);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocked dot product equals the plain f64 sum: over lengths that end inside a
    /// lane group and inside a block, with every component weighing in.
    #[test]
    fn dot_sums_every_particle_of_every_component() {
        for n in [0, 1, 7, 8, 63, 64, 65, 203] {
            let wave = |seed: f32| -> Vec<f32> {
                (0..n).map(|i| (seed * (i as f32 + 1.0)).sin()).collect()
            };
            let a: Components = [wave(0.7), wave(1.3), wave(2.9)];
            let b: Components = [wave(0.4), wave(3.1), wave(1.7)];
            let exact: f64 = (0..3)
                .flat_map(|c| (0..n).map(move |i| (c, i)))
                .map(|(c, i)| a[c][i] as f64 * b[c][i] as f64)
                .sum();
            let got = dot(&a, &b);
            assert!(
                (got - exact).abs() <= 1e-6 * (1.0 + exact.abs()),
                "n = {n}: {got} vs {exact}"
            );
        }
    }
}
