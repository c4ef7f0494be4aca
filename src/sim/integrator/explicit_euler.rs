//! Explicit (forward) Euler.

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::{ClothState, Real};

/// `x ← x + v·h`, `v ← v + a(x, v)·h`, both from the start of the step. First order; its
/// energy grows by `1 + (ωh)²` per step on an undamped oscillator, so it is unstable for
/// every step on undamped cloth and needs damping to survive at all.
#[derive(Default)]
pub struct ExplicitEuler<R: Real = f32> {
    acc: Vec<R::V3>,
}

impl<R: Real> Integrator<R> for ExplicitEuler<R> {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::ExplicitEuler
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
    ) -> Result<StepReport, StepError> {
        ctx.accelerations(&state.pos, &state.vel, &mut self.acc);
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        for (((x, v), a), &w) in particles.zip(&self.acc).zip(&ctx.model.inv_mass) {
            if w != 0.0 {
                *x += *v * h;
                *v += *a * h;
            }
        }
        state.time += h.to_f64();
        Ok(ctx.report())
    }
}
