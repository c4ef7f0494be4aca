//! Implicit (backward) Euler in the Baraff–Witkin form.

use super::super::cg::{CgOutcome, ConjugateGradient};
use super::super::forces::SystemMatrix;
use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::{ClothState, Real, Vector};

/// One linearised backward-Euler step: solve
/// `(M − h·∂f/∂v − h²·∂f/∂x)·Δv = h·(f + h·(∂f/∂x)·v)` by preconditioned conjugate
/// gradients, then `v ← v + Δv`, `x ← x + h·v`. With `newton_iterations > 1` the step is
/// refined by Newton's method on `M(v' − v) = h·f(x + h·v', v')` until the residual falls
/// below `newton_tolerance` of `‖h·f‖`. First order, unconditionally stable for the
/// springs (energy of an undamped oscillator shrinks by `1/(1 + (ωh)²)` per step).
/// Forces without derivatives (none yet) would be treated explicitly.
#[derive(Default)]
pub struct ImplicitEuler<R: Real = f32> {
    force: Vec<R::V3>,
    sys: SystemMatrix<R>,
    rhs: Vec<R::V3>,
    dv: Vec<R::V3>,
    vel: Vec<R::V3>,
    pos: Vec<R::V3>,
    cg: ConjugateGradient<R>,
    /// The step length at which `dv` (and `previous_dv`, when as long) are the last steps'
    /// solutions, from which a step of that length makes its first guess
    /// ([`ImplicitEuler::guess`]); `None` when there are none.
    warm: Option<R>,
    /// The Δv of the step before the last.
    previous_dv: Vec<R::V3>,
    /// Starts each solve from the last step's Δv alone (for comparisons).
    last_step_guess: bool,
}

impl<R: Real> ImplicitEuler<R> {
    /// One whose solves start from the last step's Δv, not extrapolated (for comparisons).
    pub fn last_step_guess() -> Self {
        Self {
            last_step_guess: true,
            ..Self::default()
        }
    }

    /// Turns `dv` into this step's first guess for the solve: the last two steps' Δv
    /// extrapolated linearly (`2·Δv₁ − Δv₂`), the last one alone after a single step,
    /// and zero when the state changed outside since or the step length `h` is not theirs
    /// (no history: a guard that relaxes its substeps changes it). Only a starting
    /// point: the solve still runs to its tolerance, in fewer iterations (on the
    /// bench scene 27 instead of 29 a step).
    fn guess(&mut self, h: R) {
        if self.warm != Some(h) {
            self.dv.clear();
            self.previous_dv.clear();
            return;
        }
        if self.last_step_guess {
            return;
        }
        if self.previous_dv.len() == self.dv.len() {
            for (d, previous) in self.dv.iter_mut().zip(&mut self.previous_dv) {
                let last = *d;
                *d = last * R::of_f32(2.0) - *previous;
                *previous = last;
            }
        } else {
            self.previous_dv.clone_from(&self.dv);
        }
    }

    /// Solves `sys·dv = rhs` through the context (timed and counted as the solve phase).
    fn solve(&mut self, ctx: &mut StepContext<'_, R>) -> Result<(), StepError> {
        let (model, config) = (ctx.model, *ctx.config);
        let (cg, sys, rhs, dv) = (&mut self.cg, &self.sys, &self.rhs, &mut self.dv);
        let outcome: Result<CgOutcome, StepError> = ctx.solve(|| {
            let out = cg.solve(model, sys, rhs, dv, config.tolerance, config.max_iterations);
            let (iterations, residual, converged) = match &out {
                Ok(o) => (o.iterations, Some(o.residual), o.converged),
                Err(StepError::Breakdown { iterations } | StepError::NonFinite { iterations }) => {
                    (*iterations, None, false)
                }
                Err(StepError::Unsupported(_) | StepError::Device(_) | StepError::Contact(_)) => {
                    (0, None, false)
                }
            };
            (out, iterations, residual, converged)
        });
        outcome.map(drop)
    }
}

impl<R: Real> Integrator<R> for ImplicitEuler<R> {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::ImplicitEuler
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
    ) -> Result<StepReport, StepError> {
        let model = ctx.model;
        ctx.forces_where(&state.pos, &state.vel, |_| true, &mut self.force);
        let sys = &mut self.sys;
        ctx.derivative_work(|m, f| f.assemble(m, &state.pos, &state.vel, h, sys));
        self.rhs.clear();
        let sys = &self.sys;
        self.rhs
            .extend((self.force.iter().enumerate()).map(|(i, f)| (*f + sys.dfdx_v(i) * h) * h));
        let force_scale = self
            .rhs
            .iter()
            .map(|r| r.length_squared())
            .sum::<R>()
            .sqrt();
        self.guess(h);
        // Until this step succeeds, `dv` is no solution to start from.
        self.warm = None;
        self.solve(ctx)?;
        self.vel.clear();
        self.vel
            .extend(state.vel.iter().zip(&self.dv).map(|(v, d)| *v + *d));
        for _ in 1..ctx.config.newton_iterations {
            // Residual of backward Euler at the current velocity guess.
            self.pos.clear();
            self.pos
                .extend(state.pos.iter().zip(&self.vel).map(|(x, v)| *x + *v * h));
            ctx.forces_where(&self.pos, &self.vel, |_| true, &mut self.force);
            self.rhs.clear();
            for i in 0..self.vel.len() {
                let g = (self.vel[i] - state.vel[i]) * R::of_f32(model.mass[i]) - self.force[i] * h;
                self.rhs.push(if model.inv_mass[i] > 0.0 {
                    -g
                } else {
                    R::V3::ZERO
                });
            }
            let residual = self
                .rhs
                .iter()
                .map(|r| r.length_squared())
                .sum::<R>()
                .sqrt();
            if residual <= R::of_f32(ctx.config.newton_tolerance) * force_scale {
                break;
            }
            let (pos, vel, sys) = (&self.pos, &self.vel, &mut self.sys);
            ctx.derivative_work(|m, f| f.assemble(m, pos, vel, h, sys));
            // A Newton correction starts from zero; the step's Δv is kept for the next step.
            let step_dv = std::mem::take(&mut self.dv);
            self.solve(ctx)?;
            for (v, d) in self.vel.iter_mut().zip(&self.dv) {
                *v += *d;
            }
            self.dv = step_dv;
        }
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        for (((x, v), v_new), &w) in particles.zip(&self.vel).zip(&model.inv_mass) {
            if w != 0.0 {
                *v = *v_new;
                *x += *v * h;
            }
        }
        state.time += h.to_f64();
        self.warm = Some(h);
        Ok(ctx.report())
    }

    /// The state changed outside: the last Δv is no longer a good guess.
    fn invalidate(&mut self) {
        self.warm = None;
    }
}
