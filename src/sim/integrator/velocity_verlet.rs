//! Velocity Verlet.

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::{ClothState, Real};

/// `x ← x + v·h + ½a·h²`, `a' = a(x', v + a·h)`, `v ← v + ½(a + a')·h`.
///
/// The end-of-step acceleration `a'` is kept for the next step, so a step costs one force
/// evaluation. It is dropped by [`Integrator::invalidate`] — after a contact changed
/// velocities, a pin or density change, new parameters, a rollback — and then recomputed
/// from the state as it is.
#[derive(Default)]
pub struct VelocityVerlet<R: Real = f32> {
    acc: Vec<R::V3>,
    acc_next: Vec<R::V3>,
    predicted: Vec<R::V3>,
    /// Whether `acc` belongs to the current state.
    kept: bool,
}

impl<R: Real> Integrator<R> for VelocityVerlet<R> {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Verlet
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
    ) -> Result<StepReport, StepError> {
        if !self.kept || self.acc.len() != state.pos.len() {
            ctx.accelerations(&state.pos, &state.vel, &mut self.acc);
        }
        let w = &ctx.model.inv_mass;
        self.predicted.clear();
        self.predicted.extend_from_slice(&state.vel);
        let particles = state.pos.iter_mut().zip(&state.vel);
        let kept = self.acc.iter().zip(self.predicted.iter_mut());
        for (((x, v), (a, predicted)), &w) in particles.zip(kept).zip(w) {
            if w != 0.0 {
                *x += *v * h + *a * (R::of_f32(0.5) * h * h);
                // Velocity-dependent forces (damping) are evaluated at a first-order prediction.
                *predicted += *a * h;
            }
        }
        ctx.accelerations(&state.pos, &self.predicted, &mut self.acc_next);
        let both = self.acc.iter().zip(&self.acc_next);
        for ((v, (a, a_next)), &w) in state.vel.iter_mut().zip(both).zip(w) {
            if w != 0.0 {
                *v += (*a + *a_next) * (R::of_f32(0.5) * h);
            }
        }
        std::mem::swap(&mut self.acc, &mut self.acc_next);
        self.kept = true;
        state.time += h.to_f64();
        Ok(ctx.report())
    }

    fn invalidate(&mut self) {
        self.kept = false;
    }
}
