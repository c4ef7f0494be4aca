//! Preconditioned conjugate gradients on the implicit system, with pinned particles
//! filtered out of the solve (their unknowns stay zero) and a block-Jacobi preconditioner.

use std::ops::Range;

use crate::cloth::{ClothModel, Matrix, Real, Vector};
use crate::parallel::{Disjoint, each_block, each_part, sum_blocks};

use super::forces::SystemMatrix;
use super::integrator::StepError;
use super::kernels::{Blocks, Components, at, blocks_times_in, split, zeroed};

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
    /// Each block's partial sums in a section ([`sum_blocks`]).
    partials: Vec<[f64; 2]>,
}

/// Particles of a block of the dot products: its partial sum is the unit the sums add up
/// by, whoever runs it.
const BLOCK: usize = 64;

/// `Σ a_i·b_i` over one block of at most [`BLOCK`] particles (`a` and `b` its elements):
/// eight f32 lanes, eight particles each, side by side in the vector units, then the lanes
/// in f64. The blocks' sums add up in f64 ([`sum_blocks`]); one f64 running sum was a
/// chain of dependent additions, an eighth of an implicit step's time.
#[inline(always)]
fn block_dot<R: Real>(a: [&[R]; 3], b: [&[R]; 3]) -> f64 {
    const LANES: usize = 8;
    let zero = [R::ZERO; LANES];
    let lanes_of = |v: &[R]| -> [R; LANES] { v.try_into().unwrap_or(zero) };
    let len = a.iter().chain(&b).map(|v| v.len()).min().unwrap_or(0);
    let whole = len / LANES * LANES;
    let mut sum = zero;
    for k in (0..whole).step_by(LANES) {
        for c in 0..3 {
            let (u, v) = (lanes_of(&a[c][k..k + LANES]), lanes_of(&b[c][k..k + LANES]));
            for l in 0..LANES {
                sum[l] += u[l] * v[l];
            }
        }
    }
    for i in whole..len {
        sum[0] += a[0][i] * b[0][i] + a[1][i] * b[1][i] + a[2][i] * b[2][i];
    }
    sum.iter().map(|s| s.to_f64()).sum::<f64>()
}

/// The three components of `v`, for disjoint parts taken by the pieces of a section.
fn disjoint<R>(v: &mut Components<R>) -> [Disjoint<'_, R>; 3] {
    let [x, y, z] = v;
    [x, y, z].map(|c| Disjoint::new(&mut c[..]))
}

/// Elements `range` of each of `v`'s components.
///
/// # Safety
/// As [`Disjoint::part`]: no other piece uses these elements meanwhile.
#[allow(clippy::mut_from_ref)]
unsafe fn parts<'a, R>(v: &'a [Disjoint<'_, R>; 3], range: &Range<usize>) -> [&'a mut [R]; 3] {
    // SAFETY: by the caller's contract.
    v.each_ref().map(|c| unsafe { c.part(range.clone()) })
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
        for v in [&mut self.r, &mut self.z, &mut self.p] {
            v.iter_mut().for_each(|c| c.resize(n, R::ZERO));
        }
        self.precond.iter_mut().for_each(|e| e.resize(n, R::ZERO));
        zeroed(&mut self.q, n);
        split(x, &mut self.x, n);
        // r = b − A·x for the starting guess, the preconditioner M⁻¹ (the diagonal blocks'
        // inverses), z = M⁻¹·r, p = z, and r·z, r·r; q cleared for the first product.
        sys.add_coupling(&self.x, &mut self.q);
        let (diagonal, x_start) = (sys.diagonal(), &self.x);
        let [q, r, z, p] = [&mut self.q, &mut self.r, &mut self.z, &mut self.p].map(disjoint);
        let precond = self.precond.each_mut().map(|e| Disjoint::new(&mut e[..]));
        let [mut rz, rr] = sum_blocks(n, BLOCK, &mut self.partials, |range, sums| {
            let (free, b) = (&free[range.clone()], &b[range.clone()]);
            // SAFETY: each piece's elements are its own.
            let [mut q, mut r, mut z, p] = [&q, &r, &z, &p].map(|v| unsafe { parts(v, &range) });
            let mut m = precond.each_ref().map(|e| unsafe { e.part(range.clone()) });
            let d = at(diagonal, &range);
            blocks_times_in(
                d,
                at(x_start, &range),
                q.each_mut().map(|c| &mut **c),
                |d, s| d - s,
            );
            for (c, r) in r.iter_mut().enumerate() {
                for (i, r) in r.iter_mut().enumerate() {
                    *r = if free[i] {
                        b[i].to_array()[c] - q[c][i]
                    } else {
                        R::ZERO
                    };
                }
            }
            for (i, &free) in free.iter().enumerate() {
                let inverse = if free {
                    sys.diag_block(range.start + i).inverse()
                } else {
                    R::M3::ZERO
                };
                let columns = [0, 1, 2].map(|c| inverse.col(c).to_array());
                for (e, entry) in m.iter_mut().enumerate() {
                    entry[i] = columns[e / 3][e % 3];
                }
            }
            let r = r.each_mut().map(|c| &**c);
            blocks_times_in(
                m.each_mut().map(|e| &**e),
                r,
                z.each_mut().map(|c| &mut **c),
                |z, _| z,
            );
            for ((p, z), q) in p.into_iter().zip(&z).zip(q) {
                p.copy_from_slice(z);
                q.fill(R::ZERO);
            }
            let z = z.each_mut().map(|c| &**c);
            each_block(range.len(), BLOCK, sums, |b| {
                let r = at(&r, &b);
                [block_dot(r, at(&z, &b)), block_dot(r, r)]
            });
        });
        let target = tolerance as f64 * b_norm;
        let mut residual = rr.sqrt();
        let mut iterations = 0;
        // Each iteration's loops over particles run a block at a time on the team, in three
        // sections around the springs' products (which share the team themselves); the
        // sums come out the same on any number of threads.
        while iterations < max_iterations && residual > target {
            iterations += 1;
            // q = A·p, zero at pinned particles, and p·q.
            sys.add_coupling(&self.p, &mut self.q);
            let (diagonal, p) = (sys.diagonal(), &self.p);
            let q = disjoint(&mut self.q);
            let [curvature, _] = sum_blocks(n, BLOCK, &mut self.partials, |range, sums| {
                let p = at(p, &range);
                // SAFETY: each piece's elements are its own.
                let mut q = unsafe { parts(&q, &range) };
                blocks_times_in(
                    at(diagonal, &range),
                    p,
                    q.each_mut().map(|c| &mut **c),
                    |d, sums| d - sums,
                );
                let free = &free[range.clone()];
                for q in q.iter_mut() {
                    q.iter_mut().zip(free).for_each(|(q, &free)| {
                        *q = if free { *q } else { R::ZERO };
                    });
                }
                let q = q.each_mut().map(|c| &**c);
                each_block(range.len(), BLOCK, sums, |b| {
                    [block_dot(at(&p, &b), at(&q, &b)), 0.0]
                });
            });
            if !curvature.is_finite() {
                return Err(StepError::NonFinite { iterations });
            }
            if curvature <= 0.0 {
                return Err(StepError::Breakdown { iterations });
            }
            let alpha = R::of_f64(rz / curvature);
            // x += α·p, r −= α·q, z = M⁻¹·r, and r·r, r·z.
            let (p, q, precond) = (&self.p, &self.q, &self.precond);
            let (x, r, z) = (
                disjoint(&mut self.x),
                disjoint(&mut self.r),
                disjoint(&mut self.z),
            );
            let [rr, rz_next] = sum_blocks(n, BLOCK, &mut self.partials, |range, sums| {
                let p = at(p, &range);
                let q = at(q, &range);
                // SAFETY: each piece's elements are its own.
                let (x, mut r, mut z) =
                    unsafe { (parts(&x, &range), parts(&r, &range), parts(&z, &range)) };
                for (x, p) in x.into_iter().zip(p) {
                    x.iter_mut().zip(p).for_each(|(x, &p)| *x += p * alpha);
                }
                for (r, q) in r.iter_mut().zip(q) {
                    r.iter_mut().zip(q).for_each(|(r, &q)| *r -= q * alpha);
                }
                let r = r.each_mut().map(|c| &**c);
                blocks_times_in(
                    at(precond, &range),
                    r,
                    z.each_mut().map(|c| &mut **c),
                    |z, _| z,
                );
                let z = z.each_mut().map(|c| &**c);
                each_block(range.len(), BLOCK, sums, |b| {
                    let r = at(&r, &b);
                    [block_dot(r, r), block_dot(r, at(&z, &b))]
                });
            });
            residual = rr.sqrt();
            let beta = R::of_f64(rz_next / rz);
            rz = rz_next;
            // p = z + β·p, and q cleared for the next product (no sums: shared as any
            // loop over particles is).
            let z = &self.z;
            let ([p0, p1, p2], [q0, q1, q2]) = (&mut self.p, &mut self.q);
            each_part(
                [p0, p1, p2, q0, q1, q2],
                |range, [p0, p1, p2, q0, q1, q2]| {
                    for (p, z) in [p0, p1, p2].into_iter().zip(z) {
                        let z = &z[range.clone()];
                        p.iter_mut().zip(z).for_each(|(p, &z)| *p = z + *p * beta);
                    }
                    [q0, q1, q2].into_iter().for_each(|q| q.fill(R::ZERO));
                },
            );
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

    /// A block's dot product equals the plain f64 sum: over lengths that end inside a
    /// lane group, a whole block, and a shorter last block, with every component weighing
    /// in.
    #[test]
    fn a_blocks_dot_sums_every_particle_of_every_component() {
        for n in [0, 1, 7, 8, 63, 64] {
            let wave = |seed: f32| -> Vec<f32> {
                (0..n).map(|i| (seed * (i as f32 + 1.0)).sin()).collect()
            };
            let a: Components = [wave(0.7), wave(1.3), wave(2.9)];
            let b: Components = [wave(0.4), wave(3.1), wave(1.7)];
            let exact: f64 = (0..3)
                .flat_map(|c| (0..n).map(move |i| (c, i)))
                .map(|(c, i)| a[c][i] as f64 * b[c][i] as f64)
                .sum();
            let got = block_dot(a.each_ref().map(|c| &c[..]), b.each_ref().map(|c| &c[..]));
            assert!(
                (got - exact).abs() <= 1e-6 * (1.0 + exact.abs()),
                "n = {n}: {got} vs {exact}"
            );
        }
    }
}
