//! The classical fourth-order Runge–Kutta method.

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::{ClothState, Real, Vector};

/// Four slopes — at the start, twice at the midpoint, at the end — weighted 1:2:2:1.
/// Fourth order, four force evaluations; stable for `ωh` up to 2√2 on an undamped
/// oscillator (and slightly dissipative there).
#[derive(Default)]
pub struct Rk4<R: Real = f32> {
    acc: Vec<R::V3>,
    stage_pos: Vec<R::V3>,
    stage_vel: Vec<R::V3>,
    /// Weighted sums of the slopes of x (velocities) and of v (accelerations).
    sum_vel: Vec<R::V3>,
    sum_acc: Vec<R::V3>,
}

impl<R: Real> Rk4<R> {
    /// Adds `weight ×` the current stage's slopes (`stage_vel`, `acc`) to the sums and, when
    /// `next` is given, sets the next stage to `start + next × slope`.
    fn accumulate(&mut self, state: &ClothState<R>, weight: R, next: Option<R>) {
        for i in 0..state.pos.len() {
            let (k_x, k_v) = (self.stage_vel[i], self.acc[i]);
            self.sum_vel[i] += k_x * weight;
            self.sum_acc[i] += k_v * weight;
            if let Some(c) = next {
                self.stage_pos[i] = state.pos[i] + k_x * c;
                self.stage_vel[i] = state.vel[i] + k_v * c;
            }
        }
    }
}

impl<R: Real> Integrator<R> for Rk4<R> {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Rk4
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
    ) -> Result<StepReport, StepError> {
        let n = state.pos.len();
        self.stage_pos.clone_from(&state.pos);
        self.stage_vel.clone_from(&state.vel);
        self.sum_vel.clear();
        self.sum_vel.resize(n, R::V3::ZERO);
        self.sum_acc.clear();
        self.sum_acc.resize(n, R::V3::ZERO);
        let (one, two, half) = (R::ONE, R::of_f32(2.0), R::of_f32(0.5) * h);
        for (weight, next) in [
            (one, Some(half)),
            (two, Some(half)),
            (two, Some(h)),
            (one, None),
        ] {
            ctx.accelerations(&self.stage_pos, &self.stage_vel, &mut self.acc);
            self.accumulate(state, weight, next);
        }
        let sixth = h / R::of_f32(6.0);
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        let sums = self.sum_vel.iter().zip(&self.sum_acc);
        for (((x, v), (dx, dv)), &w) in particles.zip(sums).zip(&ctx.model.inv_mass) {
            if w != 0.0 {
                *x += *dx * sixth;
                *v += *dv * sixth;
            }
        }
        state.time += h.to_f64();
        Ok(ctx.report())
    }
}
