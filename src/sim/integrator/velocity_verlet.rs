//! Velocity Verlet.

use glam::Vec3;

use super::{Integrator, IntegratorKind, StepContext};
use crate::cloth::ClothState;

/// `x ← x + v·h + ½a·h²`, `a' = a(x', v + a·h)`, `v ← v + ½(a + a')·h`.
///
/// The end-of-step acceleration `a'` is kept for the next step, so a step costs one force
/// evaluation. It is recomputed when the state is not the one it was computed for (another
/// state, a reset, a changed particle count). Colliders change positions and velocities
/// after the step; the kept `a'` then lags by that contact correction, which is of the
/// order of the (already non-smooth) collision response itself.
#[derive(Default)]
pub struct VelocityVerlet {
    acc: Vec<Vec3>,
    acc_next: Vec<Vec3>,
    predicted: Vec<Vec3>,
    /// Simulated time the kept acceleration belongs to.
    acc_time: Option<f64>,
}

impl Integrator for VelocityVerlet {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Verlet
    }

    fn step(&mut self, ctx: &mut StepContext<'_>, state: &mut ClothState, h: f32) {
        if self.acc_time != Some(state.time) || self.acc.len() != state.pos.len() {
            ctx.acceleration(&state.pos, &state.vel, &mut self.acc);
        }
        let start = std::time::Instant::now();
        let w = &ctx.model.inv_mass;
        state.prev_pos.copy_from_slice(&state.pos);
        self.predicted.clear();
        self.predicted.extend_from_slice(&state.vel);
        let particles = state.pos.iter_mut().zip(&state.vel);
        let kept = self.acc.iter().zip(self.predicted.iter_mut());
        for (((x, v), (a, predicted)), &w) in particles.zip(kept).zip(w) {
            if w != 0.0 {
                *x += *v * h + *a * (0.5 * h * h);
                // Velocity-dependent forces (damping) are evaluated at a first-order prediction.
                *predicted += *a * h;
            }
        }
        let mut elapsed = start.elapsed();
        ctx.acceleration(&state.pos, &self.predicted, &mut self.acc_next);
        let start = std::time::Instant::now();
        let both = self.acc.iter().zip(&self.acc_next);
        for ((v, (a, a_next)), &w) in state.vel.iter_mut().zip(both).zip(w) {
            if w != 0.0 {
                *v += (*a + *a_next) * (0.5 * h);
            }
        }
        std::mem::swap(&mut self.acc, &mut self.acc_next);
        state.time += h as f64;
        self.acc_time = Some(state.time);
        elapsed += start.elapsed();
        ctx.timings.add("integrate", elapsed);
    }
}
