//! Semi-implicit (symplectic) Euler.

use glam::Vec3;

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::step::{Integrator, StepError, StepReport};
use crate::cloth::ClothState;
use crate::sim::forces::{Components, split};

/// `v ← v + a(x, v)·h`, then `x ← x + v·h` with the new velocity.
///
/// When every force term takes its vectors one array per component (gravity, springs, air
/// damping: the usual scene), the state is copied into such arrays once and the forces are
/// summed there, in one vector loop per term and component; otherwise per vector. Both give
/// the same bits.
#[derive(Default)]
pub struct SemiImplicitEuler {
    acc: Vec<Vec3>,
    pos: Components,
    vel: Components,
    force: Components,
    /// Never takes the component path (tests compare the two).
    whole_vectors: bool,
}

impl SemiImplicitEuler {
    /// One that always sums forces per vector (the general path), for comparisons.
    pub fn whole_vectors() -> Self {
        Self {
            whole_vectors: true,
            ..Self::default()
        }
    }

    /// The step on component arrays; false (nothing changed) when a term cannot take them.
    fn step_components(
        &mut self,
        ctx: &mut StepContext<'_>,
        state: &mut ClothState,
        h: f32,
    ) -> bool {
        if self.whole_vectors || !ctx.forces.takes_components() {
            return false;
        }
        let n = state.pos.len();
        split(&state.pos, &mut self.pos, n);
        split(&state.vel, &mut self.vel, n);
        if !ctx.forces_components(&self.pos, &self.vel, &mut self.force) {
            return false;
        }
        let [fx, fy, fz] = &self.force;
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        for (p, ((x, v), &w)) in particles.zip(&ctx.model.inv_mass).enumerate() {
            if w != 0.0 {
                let a = Vec3::new(fx[p], fy[p], fz[p]) * w;
                *v += a * h;
                *x += *v * h;
            }
        }
        true
    }
}

impl Integrator for SemiImplicitEuler {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::SemiImplicitEuler
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_>,
        state: &mut ClothState,
        h: f32,
    ) -> Result<StepReport, StepError> {
        if self.step_components(ctx, state, h) {
            state.time += h as f64;
            return Ok(ctx.report());
        }
        ctx.accelerations(&state.pos, &state.vel, &mut self.acc);
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        for (((x, v), a), &w) in particles.zip(&self.acc).zip(&ctx.model.inv_mass) {
            if w != 0.0 {
                *v += *a * h;
                *x += *v * h;
            }
        }
        state.time += h as f64;
        Ok(ctx.report())
    }
}
