//! Hookean springs with a dashpot along the spring:
//! `f_a = [k(|d| − l₀) + c·(v_b − v_a)·d̂] d̂`, `f_b = −f_a`, `d = x_b − x_a`.
//!
//! Besides the forces this gives their derivatives, per spring as the 3×3 blocks
//! `K_x = ∂f_a/∂x_b` and `K_v = ∂f_a/∂v_b` (then `∂f_a/∂x_a = −K_x`, `∂f_b/∂x_b = −K_x`,
//! `∂f_b/∂x_a = K_x`), and as matrix-free actions on a vector.

use std::ops::Range;
use std::sync::OnceLock;

use crate::cloth::{ClothModel, Matrix, Real, Springs, Vector};

use crate::sim::kernels::{Components, SpringRuns, TwoPasses};

use super::force_term::{ForceTerm, Fused};
use super::jacobian::{JacobianMode, SystemMatrix};
use crate::sim::constraints::DistanceConstraints;
use crate::sim::params::Material;

/// Springs with per-kind stiffness (N/m) and damping (N·s/m), expanded per spring, over a
/// range of the model's springs: the structural and shear springs are one term, the bend
/// springs (the last ones) another, present only when the scene bends by springs.
#[derive(Clone, Debug, PartialEq)]
pub struct SpringForce {
    stiffness: [f32; 3],
    damping: [f32; 3],
    range: Range<usize>,
    /// Stiffness of each spring in the range, N/m.
    k: Vec<f32>,
    /// Damping of each spring in the range, N·s/m.
    c: Vec<f32>,
    /// The same springs regrouped for fast force evaluation, built on the first evaluation
    /// (a term only asked for derivatives or constraints never needs them).
    runs: LazyRuns,
}

/// Derived from the springs, so not part of the term's value: clones keep it, comparisons
/// ignore it.
#[derive(Clone, Debug, Default)]
struct LazyRuns(OnceLock<SpringRuns>);

impl PartialEq for LazyRuns {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The derivative blocks of one spring.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringBlocks<R: Real = f32> {
    /// `∂f_a/∂x_b`, N/m.
    pub dx: R::M3,
    /// `∂f_a/∂v_b`, N·s/m.
    pub dv: R::M3,
}

/// `u vᵀ`.
fn outer<R: Real>(u: R::V3, v: R::V3) -> R::M3 {
    R::M3::from_cols(u * v.x(), u * v.y(), u * v.z())
}

impl SpringForce {
    /// Per-kind strengths expanded over all of `springs`.
    pub fn new(springs: &Springs, stiffness: [f32; 3], damping: [f32; 3]) -> Self {
        Self::over(springs, 0..springs.len(), stiffness, damping)
    }

    /// Per-kind strengths expanded over `range` of `springs` (clamped to the springs there are).
    pub fn over(
        springs: &Springs,
        range: Range<usize>,
        stiffness: [f32; 3],
        damping: [f32; 3],
    ) -> Self {
        let end = range.end.min(springs.len());
        let range = range.start.min(end)..end;
        let mut s = Self {
            stiffness,
            damping,
            range,
            k: Vec::new(),
            c: Vec::new(),
            runs: LazyRuns::default(),
        };
        s.expand(springs);
        s
    }

    /// Changes the strengths; re-expands only when they changed.
    pub fn set_strengths(&mut self, springs: &Springs, stiffness: [f32; 3], damping: [f32; 3]) {
        if (self.stiffness, self.damping) != (stiffness, damping) {
            self.stiffness = stiffness;
            self.damping = damping;
            self.expand(springs);
        }
    }

    /// The springs this term covers.
    pub fn range(&self) -> Range<usize> {
        self.range.clone()
    }

    fn expand(&mut self, springs: &Springs) {
        let kinds = &springs.kind[self.range.clone()];
        self.k = kinds.iter().map(|k| self.stiffness[k.index()]).collect();
        self.c = kinds.iter().map(|k| self.damping[k.index()]).collect();
        if let Some(runs) = self.runs.0.get_mut() {
            runs.set_strengths(&self.k, &self.c);
        }
    }

    /// The runs of these springs, built the first time they are needed.
    fn runs(&self, springs: &Springs) -> &SpringRuns {
        self.runs.0.get_or_init(|| {
            let r = self.range.clone();
            let (a, b) = (&springs.a[r.clone()], &springs.b[r.clone()]);
            let particles = a.iter().chain(b).map(|&p| p as usize + 1).max();
            SpringRuns::new(
                particles.unwrap_or(0),
                a,
                b,
                &springs.rest[r],
                &self.k,
                &self.c,
            )
        })
    }

    /// Each spring's index (into the model's springs) with its stiffness and damping.
    pub fn each(&self) -> impl Iterator<Item = (usize, f32, f32)> + '_ {
        self.range
            .clone()
            .zip(self.k.iter().zip(&self.c))
            .map(|(e, (&k, &c))| (e, k, c))
    }

    /// Adds every spring's force (N) to `f`, in parallel for large cloths, with the same
    /// result on any number of threads: in `f32` through the vectorised runs, in `f64`
    /// spring by spring ([`SpringForce::add_forces_plain`]).
    pub fn add_forces<R: Real>(
        &self,
        springs: &Springs,
        pos: &[R::V3],
        vel: &[R::V3],
        f: &mut [R::V3],
    ) {
        match (R::f32_slice(pos), R::f32_slice(vel), R::f32_slice_mut(f)) {
            (Some(pos), Some(vel), Some(f)) => self.runs(springs).add_forces(pos, vel, f),
            _ => self.add_forces_plain::<R>(springs, pos, vel, f),
        }
    }

    /// The forces of [`SpringForce::add_forces`] computed one spring at a time, in any
    /// precision: `f_a = [k(|d| − l₀) + c·(v_b − v_a)·d̂] d̂`, `f_b = −f_a`.
    pub fn add_forces_plain<R: Real>(
        &self,
        springs: &Springs,
        pos: &[R::V3],
        vel: &[R::V3],
        f: &mut [R::V3],
    ) {
        for (e, k, c) in self.each() {
            let (a, b) = (springs.a[e] as usize, springs.b[e] as usize);
            let d = pos[b] - pos[a];
            let len = d.length();
            if len <= R::TINY_LENGTH {
                continue;
            }
            let n = d / len;
            let stretch = len - R::of_f32(springs.rest[e]);
            let closing = (vel[b] - vel[a]).dot(n);
            let pull = n * (R::of_f32(k) * stretch + R::of_f32(c) * closing);
            f[a] += pull;
            f[b] -= pull;
        }
    }

    /// As [`SpringForce::add_forces`] with positions, velocities and forces stored one array
    /// per component: the same bits.
    pub fn add_forces_components(
        &self,
        springs: &Springs,
        pos: &Components,
        vel: &Components,
        f: &mut Components,
    ) {
        self.runs(springs).add_forces_components(pos, vel, f);
    }

    /// The forces in two passes (see `SpringRuns::two_passes`).
    pub fn two_passes<'a>(&'a self, springs: &Springs) -> TwoPasses<'a> {
        TwoPasses::of(self.runs(springs))
    }

    /// `Σ ½k(|d| − l₀)²`, joules.
    pub fn potential_energy<R: Real>(&self, springs: &Springs, pos: &[R::V3]) -> f64 {
        self.each()
            .map(|(e, k, _)| {
                let d = pos[springs.b[e] as usize].distance(pos[springs.a[e] as usize]);
                let stretch = (d - R::of_f32(springs.rest[e])).to_f64();
                0.5 * k as f64 * stretch * stretch
            })
            .sum()
    }

    /// The derivative blocks of spring `e` (an index into the model's springs, in range).
    ///
    /// [`JacobianMode::Exact`] is the true derivative. [`JacobianMode::Definite`] is the
    /// usual implicit-solver form: the transverse stiffness `k(1 − l₀/|d|)` of a compressed
    /// spring is clamped to zero (it would be negative and make the system indefinite) and
    /// the dashpot's dependence on the spring's direction is dropped, so `dx` is symmetric
    /// positive semi-definite.
    pub fn blocks<R: Real>(
        &self,
        springs: &Springs,
        pos: &[R::V3],
        vel: &[R::V3],
        e: usize,
        mode: JacobianMode,
    ) -> SpringBlocks<R> {
        let (a, b) = (springs.a[e] as usize, springs.b[e] as usize);
        let d = pos[b] - pos[a];
        let len = d.length();
        if len <= R::TINY_LENGTH {
            return SpringBlocks {
                dx: R::M3::ZERO,
                dv: R::M3::ZERO,
            };
        }
        let n = d / len;
        let nn = outer::<R>(n, n);
        let transverse = R::M3::IDENTITY - nn;
        let (k, c) = (self.k[e - self.range.start], self.c[e - self.range.start]);
        let (k, c) = (R::of_f32(k), R::of_f32(c));
        let stretch = R::ONE - R::of_f32(springs.rest[e]) / len;
        let dx = match mode {
            JacobianMode::Exact => {
                let dv = vel[b] - vel[a];
                let elastic = nn * k + transverse * (k * stretch);
                let viscous = (outer::<R>(n, transverse * dv) + transverse * dv.dot(n)) * (c / len);
                elastic + viscous
            }
            JacobianMode::Definite => nn * k + transverse * (k * stretch.max(R::ZERO)),
        };
        SpringBlocks { dx, dv: nn * c }
    }

    /// Adds `(∂f/∂x)·u` to `out`, with the blocks of `mode`, computed on the fly.
    pub fn add_df_dx<R: Real>(
        &self,
        springs: &Springs,
        pos: &[R::V3],
        vel: &[R::V3],
        u: &[R::V3],
        mode: JacobianMode,
        out: &mut [R::V3],
    ) {
        for e in self.range.clone() {
            let block = self.blocks::<R>(springs, pos, vel, e, mode).dx;
            apply_pair::<R>(springs, e, block, u, out);
        }
    }

    /// Adds `(∂f/∂v)·u` to `out` (the dashpots; exact in either mode).
    pub fn add_df_dv<R: Real>(
        &self,
        springs: &Springs,
        pos: &[R::V3],
        vel: &[R::V3],
        u: &[R::V3],
        out: &mut [R::V3],
    ) {
        for e in self.range.clone() {
            let block = (self.blocks::<R>(springs, pos, vel, e, JacobianMode::Definite)).dv;
            apply_pair::<R>(springs, e, block, u, out);
        }
    }

    /// Adds every spring's definite blocks to the implicit system. The blocks of
    /// [`SpringForce::blocks`] in definite form are `K_x = k·s·I + k(1 − s)·n nᵀ` (with
    /// `s = max(0, 1 − l₀/|d|)`) and `K_v = c·n nᵀ`, so the system's block is
    /// `S_e = h·K_v + h²·K_x = α·I + β·n nᵀ` and `K_x·(v_b − v_a) = k·s·w + k(1 − s)(n·w)·n`:
    /// built from those scalars directly, a third of the arithmetic of the 3×3 products, in
    /// the vector loops of the springs' runs, for every spring term at once when the
    /// matrix is finished ([`SystemMatrix::add_springs`]).
    pub fn add_to_system<R: Real>(&self, springs: &Springs, sys: &mut SystemMatrix<R>) {
        sys.add_springs(springs, self.range(), (&self.k, &self.c));
    }

    /// The same springs as distance constraints for position-based methods: rest length
    /// and compliance `1/k` (m/N). Springs of zero stiffness are no constraint and are left out.
    pub fn constraints(&self, springs: &Springs) -> DistanceConstraints {
        let mut out = DistanceConstraints::default();
        self.add_constraints(springs, &mut out);
        out
    }

    /// Appends these springs as distance constraints to `out`.
    pub fn add_constraints(&self, springs: &Springs, out: &mut DistanceConstraints) {
        for (e, k, c) in self.each().filter(|&(_, k, _)| k > 0.0) {
            out.a.push(springs.a[e]);
            out.b.push(springs.b[e]);
            out.rest.push(springs.rest[e]);
            out.compliance.push(1.0 / k);
            out.damping.push(c);
        }
    }
}

/// One spring's share of a Jacobian–vector product: `out_a += B(u_b − u_a)`,
/// `out_b −= B(u_b − u_a)`.
fn apply_pair<R: Real>(springs: &Springs, e: usize, block: R::M3, u: &[R::V3], out: &mut [R::V3]) {
    let (a, b) = (springs.a[e] as usize, springs.b[e] as usize);
    let t = block * (u[b] - u[a]);
    out[a] += t;
    out[b] -= t;
}

impl<R: Real> ForceTerm<R> for SpringForce {
    fn retune(&mut self, model: &ClothModel, material: &Material) {
        self.set_strengths(&model.springs, material.stiffness, material.damping);
    }

    fn add_forces(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        _t: f64,
        f: &mut [R::V3],
    ) {
        SpringForce::add_forces::<R>(self, &model.springs, pos, vel, f);
    }

    fn takes_components(&self) -> bool {
        R::VECTORISED
    }

    fn add_forces_components(
        &self,
        model: &ClothModel,
        pos: &Components,
        vel: &Components,
        f: &mut Components,
    ) {
        SpringForce::add_forces_components(self, &model.springs, pos, vel, f);
    }

    fn fused<'a>(&'a self, model: &ClothModel) -> Fused<'a> {
        Fused::TwoPasses(self.two_passes(&model.springs))
    }

    fn potential_energy(&self, model: &ClothModel, pos: &[R::V3]) -> f64 {
        SpringForce::potential_energy::<R>(self, &model.springs, pos)
    }

    fn add_df_dx(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        u: &[R::V3],
        mode: JacobianMode,
        out: &mut [R::V3],
    ) {
        SpringForce::add_df_dx::<R>(self, &model.springs, pos, vel, u, mode, out);
    }

    fn add_df_dv(
        &self,
        model: &ClothModel,
        pos: &[R::V3],
        vel: &[R::V3],
        u: &[R::V3],
        out: &mut [R::V3],
    ) {
        SpringForce::add_df_dv::<R>(self, &model.springs, pos, vel, u, out);
    }

    fn add_to_system(
        &self,
        model: &ClothModel,
        _pos: &[R::V3],
        _vel: &[R::V3],
        sys: &mut SystemMatrix<R>,
    ) {
        // The blocks are computed when the matrix is finished, at the state it is given.
        SpringForce::add_to_system::<R>(self, &model.springs, sys);
    }
}
