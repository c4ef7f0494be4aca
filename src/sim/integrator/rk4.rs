//! The classical fourth-order Runge–Kutta method.

use glam::Vec3;

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::ClothState;

/// Four slopes — at the start, twice at the midpoint, at the end — weighted 1:2:2:1.
/// Fourth order, four force evaluations; stable for `ωh` up to 2√2 on an undamped
/// oscillator (and slightly dissipative there).
#[derive(Default)]
pub struct Rk4 {
    acc: Vec<Vec3>,
    stage_pos: Vec<Vec3>,
    stage_vel: Vec<Vec3>,
    /// Weighted sums of the slopes of x (velocities) and of v (accelerations).
    sum_vel: Vec<Vec3>,
    sum_acc: Vec<Vec3>,
}

impl Rk4 {
    /// Adds `weight ×` the current stage's slopes (`stage_vel`, `acc`) to the sums and, when
    /// `next` is given, sets the next stage to `start + next × slope`.
    fn accumulate(&mut self, state: &ClothState, weight: f32, next: Option<f32>) {
        for i in 0..state.pos.len() {
            let (k_x, k_v) = (self.stage_vel[i], self.acc[i]);
            self.sum_vel[i] += weight * k_x;
            self.sum_acc[i] += weight * k_v;
            if let Some(c) = next {
                self.stage_pos[i] = state.pos[i] + c * k_x;
                self.stage_vel[i] = state.vel[i] + c * k_v;
            }
        }
    }
}

impl Integrator for Rk4 {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Rk4
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_>,
        state: &mut ClothState,
        h: f32,
    ) -> Result<StepReport, StepError> {
        let n = state.pos.len();
        self.stage_pos.clone_from(&state.pos);
        self.stage_vel.clone_from(&state.vel);
        self.sum_vel.clear();
        self.sum_vel.resize(n, Vec3::ZERO);
        self.sum_acc.clear();
        self.sum_acc.resize(n, Vec3::ZERO);
        for (weight, next) in [
            (1.0, Some(0.5 * h)),
            (2.0, Some(0.5 * h)),
            (2.0, Some(h)),
            (1.0, None),
        ] {
            ctx.accelerations(&self.stage_pos, &self.stage_vel, &mut self.acc);
            self.accumulate(state, weight, next);
        }
        let sixth = h / 6.0;
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        let sums = self.sum_vel.iter().zip(&self.sum_acc);
        for (((x, v), (dx, dv)), &w) in particles.zip(sums).zip(&ctx.model.inv_mass) {
            if w != 0.0 {
                *x += *dx * sixth;
                *v += *dv * sixth;
            }
        }
        state.time += h as f64;
        Ok(ctx.report())
    }
}
