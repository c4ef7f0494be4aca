//! Semi-implicit (symplectic) Euler.

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::{ClothState, Real};
use crate::parallel::Disjoint;
use crate::parallel::wide;
use crate::sim::kernels::{Components, join, split};

/// `v ← v + a(x, v)·h`, then `x ← x + v·h` with the new velocity.
///
/// When every force term takes its vectors one array per component (gravity, springs, air
/// damping: the usual scene), the state is copied into such arrays and the forces are
/// summed there, in one vector loop per term and component; otherwise per vector. Both give
/// the same bits. A frame's substeps taken together ([`Integrator::steps`]) stay in those
/// arrays from the first to the last, and the state is written once at the end.
#[derive(Default)]
pub struct SemiImplicitEuler<R: Real = f32> {
    acc: Vec<R::V3>,
    pos: Components,
    vel: Components,
    force: Components,
    /// The step's new positions and velocities (then swapped with `pos` and `vel`).
    next_pos: Components,
    next_vel: Components,
    /// Never takes the component path (tests compare the two).
    whole_vectors: bool,
}

impl<R: Real> SemiImplicitEuler<R> {
    /// One that always sums forces per vector (the general path), for comparisons.
    pub fn whole_vectors() -> Self {
        Self {
            whole_vectors: true,
            ..Self::default()
        }
    }

    /// Whether the forces can be summed on component arrays.
    fn on_components(&self, ctx: &StepContext<'_, R>) -> bool {
        R::VECTORISED && !self.whole_vectors && ctx.forces.takes_components()
    }

    /// One step of the component arrays `self.pos`, `self.vel` (not of `state`, but for its
    /// clock). Only when [`SemiImplicitEuler::on_components`]: every term takes the arrays.
    fn advance(&mut self, ctx: &mut StepContext<'_, R>, h: f32) {
        let inv_mass = &ctx.model.inv_mass;
        // (A state and model of different sizes would step only the particles both have.)
        let n = inv_mass.len().min(self.pos[0].len()).min(self.vel[0].len());
        for next in self.next_pos.iter_mut().chain(&mut self.next_vel) {
            next.resize(n, 0.0);
        }
        let [x0, x1, x2] = &mut self.next_pos;
        let [v0, v1, v2] = &mut self.next_vel;
        let next = [x0, x1, x2, v0, v1, v2].map(|a| Disjoint::new(&mut a[..n]));
        let (pos, vel) = (&self.pos, &self.vel);
        // One range's update, from that range's forces.
        let step = |range: std::ops::Range<usize>, force: [&[f32]; 3]| {
            let w = &inv_mass[range.clone()];
            // SAFETY: the ranges are disjoint (`fused_forces` hands out disjoint ones; the
            // fallback below takes the one whole range).
            let [x0, x1, x2, v0, v1, v2] =
                next.each_ref().map(|a| unsafe { a.part(range.clone()) });
            for (c, out) in [[x0, v0], [x1, v1], [x2, v2]].into_iter().enumerate() {
                let now = [&pos[c][range.clone()], &vel[c][range.clone()], force[c]];
                update(now, w, h, out);
            }
        };
        // Each range's update as soon as its forces are summed; term by term (in one range
        // here) where the fused path does not apply.
        if !ctx.fused_forces(pos, vel, &mut self.force, step) {
            let summed = ctx.forces_components(pos, vel, &mut self.force);
            debug_assert!(summed, "a term refused component arrays it said it takes");
            step(0..n, self.force.each_ref().map(|f| &f[..n]));
        }
        std::mem::swap(&mut self.pos, &mut self.next_pos);
        std::mem::swap(&mut self.vel, &mut self.next_vel);
    }
}

impl<R: Real> Integrator<R> for SemiImplicitEuler<R> {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::SemiImplicitEuler
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
    ) -> Result<StepReport, StepError> {
        if let Some(report) = self.steps(ctx, state, h, 1) {
            return report;
        }
        ctx.accelerations(&state.pos, &state.vel, &mut self.acc);
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        for (((x, v), a), &w) in particles.zip(&self.acc).zip(&ctx.model.inv_mass) {
            if w != 0.0 {
                *v += *a * h;
                *x += *v * h;
            }
        }
        state.time += h.to_f64();
        Ok(ctx.report())
    }

    /// On component arrays from the first step to the last (no term that takes them
    /// depends on time: [`ForceTerm::takes_components`](crate::sim::forces::ForceTerm::takes_components)).
    fn steps(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
        count: u32,
    ) -> Option<Result<StepReport, StepError>> {
        if !self.on_components(ctx) {
            return None;
        }
        // The component path computes in `f32` (`on_components` asks for it).
        let (Some(pos), Some(vel)) = (
            R::f32_slice_mut(&mut state.pos),
            R::f32_slice_mut(&mut state.vel),
        ) else {
            return None;
        };
        let n = pos.len();
        split(&*pos, &mut self.pos, n);
        split(&*vel, &mut self.vel, n);
        for _ in 0..count {
            self.advance(ctx, h.to_f32());
            state.time += h.to_f64();
        }
        join(&self.pos, pos);
        join(&self.vel, vel);
        Some(Ok(ctx.report()))
    }
}

/// One component of `v' = v + (f·w)·h`, then `x' = x + v'·h`, for the particles with
/// `w ≠ 0` (the operations of the whole-vector path, in its order); the others keep `x` and
/// `v`. Written to other arrays than it reads: in place, the compiler keeps the unmoved
/// particles by masked stores, which are slow on some CPUs. Compiled plainly and for AVX2
/// (picked at run time): the same IEEE operations either way, so the same bits.
fn update(now: [&[f32]; 3], w: &[f32], h: f32, out: [&mut [f32]; 2]) {
    wide(
        #[inline(always)]
        || update_in(now, w, h, out),
    )
}

#[inline(always)]
fn update_in([x, v, f]: [&[f32]; 3], w: &[f32], h: f32, [x_out, v_out]: [&mut [f32]; 2]) {
    let n = (x.len().min(v.len()).min(f.len()).min(w.len()))
        .min(x_out.len())
        .min(v_out.len());
    let (x, v, f, w) = (&x[..n], &v[..n], &f[..n], &w[..n]);
    let (x_out, v_out) = (&mut x_out[..n], &mut v_out[..n]);
    for i in 0..n {
        let moves = w[i] != 0.0;
        let v_new = v[i] + f[i] * w[i] * h;
        let x_new = x[i] + v_new * h;
        v_out[i] = if moves { v_new } else { v[i] };
        x_out[i] = if moves { x_new } else { x[i] };
    }
}
