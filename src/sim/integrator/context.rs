//! What an integrator sees of the world: the model, the forces, its configuration, and a
//! meter through which the stepper times and counts the work.

use std::time::{Duration, Instant};

use crate::cloth::{ClothModel, Real};

use super::super::forces::{Force, ForceSet, TermTimes};
use super::super::params::SolverConfig;
use super::report::StepReport;
use crate::sim::kernels::Components;

/// Work done inside one step, filled by [`StepContext`] and read by the stepper, which
/// charges it to the phases.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepMeter {
    pub force_evals: u32,
    /// Wall time spent evaluating forces and their derivatives.
    pub forces: Duration,
    /// Of which: each force term's time and evaluations.
    pub terms: TermTimes,
    /// Of which: assembling derivatives.
    pub derivatives: Duration,
    /// Wall time spent in linear solves / constraint projection.
    pub solve: Duration,
    pub solver_iterations: u32,
    pub residual: Option<f32>,
    pub converged: bool,
}

/// The model, the forces and the configuration of one step.
pub struct StepContext<'a, R: Real = f32> {
    pub model: &'a ClothModel,
    pub forces: &'a ForceSet<R>,
    pub config: &'a SolverConfig,
    meter: &'a mut StepMeter,
}

impl<'a, R: Real> StepContext<'a, R> {
    /// A context for one step; the meter starts from zero.
    pub fn new(
        model: &'a ClothModel,
        forces: &'a ForceSet<R>,
        config: &'a SolverConfig,
        meter: &'a mut StepMeter,
    ) -> Self {
        let mut terms = std::mem::take(&mut meter.terms);
        terms.clear();
        *meter = StepMeter {
            converged: true,
            terms,
            ..StepMeter::default()
        };
        Self {
            model,
            forces,
            config,
            meter,
        }
    }

    /// Accelerations at `(pos, vel)` into `acc` (pinned particles get zero).
    pub fn accelerations(&mut self, pos: &[R::V3], vel: &[R::V3], acc: &mut Vec<R::V3>) {
        let start = Instant::now();
        let meter = &mut *self.meter;
        if (self.forces).accelerations_components(self.model, pos, vel, acc, &mut meter.terms) {
            meter.forces += start.elapsed();
            meter.force_evals += 1;
            return;
        }
        self.forces_where(pos, vel, |_| true, acc);
        super::super::forces::to_accelerations::<R>(&self.model.inv_mass, acc);
    }

    /// Forces (N) at `(pos, vel)` of the terms `keep` selects, into `f`.
    pub fn forces_where(
        &mut self,
        pos: &[R::V3],
        vel: &[R::V3],
        keep: impl Fn(&Force<R>) -> bool,
        f: &mut Vec<R::V3>,
    ) {
        let start = Instant::now();
        let meter = &mut *self.meter;
        self.forces
            .forces_timed(self.model, pos, vel, keep, f, &mut meter.terms);
        meter.forces += start.elapsed();
        meter.force_evals += 1;
    }

    /// Forces (N) of all terms on positions and velocities stored one array per component,
    /// into `f` (the same bits as [`StepContext::forces_where`] with every term); false, with
    /// nothing counted, when the scene has a term that needs the vectors whole.
    pub fn forces_components(
        &mut self,
        pos: &Components,
        vel: &Components,
        f: &mut Components,
    ) -> bool {
        if !self.forces.takes_components() {
            return false;
        }
        let start = Instant::now();
        let meter = &mut *self.meter;
        let whole =
            (self.forces).forces_components_timed(self.model, pos, vel, f, &mut meter.terms);
        meter.forces += start.elapsed();
        meter.force_evals += 1;
        whole
    }

    /// The forces as [`StepContext::forces_components`], fused with per-particle work
    /// `then(range, f)` ([`ForceSet::fused_components`]); false, with nothing done or
    /// counted, when the scene's terms do not allow it.
    pub fn fused_forces(
        &mut self,
        pos: &Components,
        vel: &Components,
        f: &mut Components,
        then: impl Fn(std::ops::Range<usize>, [&[f32]; 3]) + Sync,
    ) -> bool {
        let meter = &mut *self.meter;
        let fused = self
            .forces
            .fused_components(self.model, pos, vel, f, &mut meter.terms, then);
        if let Some(took) = fused {
            meter.forces += took;
            meter.force_evals += 1;
        }
        fused.is_some()
    }

    /// Runs a linear solve or projection `f`, charging its time to the solve phase and
    /// recording its iterations and final relative residual.
    pub fn solve<T>(&mut self, f: impl FnOnce() -> (T, u32, Option<f32>, bool)) -> T {
        let start = Instant::now();
        let (out, iterations, residual, converged) = f();
        self.meter.solve += start.elapsed();
        self.meter.solver_iterations += iterations;
        self.meter.residual = residual.or(self.meter.residual);
        self.meter.converged &= converged;
        out
    }

    /// Counts time spent in `f` as force work without counting an evaluation (assembling
    /// derivatives, say).
    pub fn derivative_work<T>(&mut self, f: impl FnOnce(&ClothModel, &ForceSet<R>) -> T) -> T {
        let start = Instant::now();
        let out = f(self.model, self.forces);
        let took = start.elapsed();
        self.meter.forces += took;
        self.meter.derivatives += took;
        out
    }

    /// What this step did so far.
    pub fn report(&self) -> StepReport {
        StepReport {
            force_evals: self.meter.force_evals,
            solver_iterations: self.meter.solver_iterations,
            residual: self.meter.residual,
            converged: self.meter.converged,
        }
    }
}
