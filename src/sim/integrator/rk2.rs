//! Second-order Runge–Kutta, midpoint form.

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::{ClothState, Real};

/// Midpoint rule: a half step of explicit Euler to `(x_m, v_m)`, then the whole step with
/// the midpoint's slopes: `x ← x + v_m·h`, `v ← v + a(x_m, v_m)·h`. Second order, two
/// force evaluations.
#[derive(Default)]
pub struct Rk2<R: Real = f32> {
    acc: Vec<R::V3>,
    mid_pos: Vec<R::V3>,
    mid_vel: Vec<R::V3>,
}

impl<R: Real> Integrator<R> for Rk2<R> {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Rk2
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
    ) -> Result<StepReport, StepError> {
        ctx.accelerations(&state.pos, &state.vel, &mut self.acc);
        let half = R::of_f32(0.5) * h;
        self.mid_pos.clear();
        self.mid_vel.clear();
        for ((x, v), a) in state.pos.iter().zip(&state.vel).zip(&self.acc) {
            self.mid_pos.push(*x + *v * half);
            self.mid_vel.push(*v + *a * half);
        }
        ctx.accelerations(&self.mid_pos, &self.mid_vel, &mut self.acc);
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        let mid = self.mid_vel.iter().zip(&self.acc);
        for (((x, v), (v_mid, a_mid)), &w) in particles.zip(mid).zip(&ctx.model.inv_mass) {
            if w != 0.0 {
                *x += *v_mid * h;
                *v += *a_mid * h;
            }
        }
        state.time += h.to_f64();
        Ok(ctx.report())
    }
}
