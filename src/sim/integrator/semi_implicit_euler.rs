//! Semi-implicit (symplectic) Euler.

use glam::Vec3;

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::step::{Integrator, StepError, StepReport};
use crate::cloth::ClothState;

/// `v ← v + a(x, v)·h`, then `x ← x + v·h` with the new velocity.
#[derive(Default)]
pub struct SemiImplicitEuler {
    acc: Vec<Vec3>,
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
