//! The CPU step backend: an integrator, the scene's forces and its colliders, advanced in
//! fixed substeps, with a guard that rolls back a diverging frame and retries it with more
//! substeps. It charges the time of every step to phases.

use std::time::{Duration, Instant};

use crate::cloth::{ClothModel, ClothState};

use super::backend::StepBackend;
use super::collider::{Collider, colliders_of};
use super::effect::Effect;
use super::forces::ForceSet;
use super::guard::{Diverged, FrameOutcome, MAX_REFINEMENTS};
use super::integrator::{Integrator, StepContext, StepError, StepMeter, StepReport};
use super::params::{SimParams, SolverConfig};
use super::stats::StepStats;
use super::timings::PhaseTimings;

/// Advances a cloth on the CPU. Built from a scene's effect list: absent effects are not in
/// it and cost nothing.
pub struct CpuStepper {
    integrator: Box<dyn Integrator>,
    forces: ForceSet,
    colliders: Vec<Collider>,
    solver: SolverConfig,
    dt: f32,
    /// Substeps per frame the parameters ask for.
    requested: u32,
    /// Substeps per frame in effect (the guard may have raised them).
    substeps: u32,
    offset: f32,
    divergence_speed: f32,
    timings: PhaseTimings,
    stats: StepStats,
    meter: StepMeter,
    /// The frame's start state, restored when a try diverges.
    backup: ClothState,
}

impl CpuStepper {
    /// A stepper for `effects` with the strengths in `params`.
    pub fn new(model: &ClothModel, params: &SimParams, effects: &[Effect]) -> Self {
        let mut stepper = Self {
            integrator: params.integrator.build(),
            forces: ForceSet::default(),
            colliders: Vec::new(),
            solver: params.solver,
            dt: params.dt,
            requested: 0,
            substeps: 1,
            offset: params.collision_offset,
            divergence_speed: params.divergence_speed,
            timings: PhaseTimings::default(),
            stats: StepStats::default(),
            meter: StepMeter::default(),
            backup: ClothState::default(),
        };
        stepper.configure(model, params, effects);
        stepper
    }

    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// Integrates one substep and charges its phases; the colliders are not applied.
    fn integrate(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
        h: f32,
    ) -> Result<StepReport, StepError> {
        let start = Instant::now();
        let result = {
            let mut ctx = StepContext::new(model, &self.forces, &self.solver, &mut self.meter);
            self.integrator.step(&mut ctx, state, h)
        };
        let total = start.elapsed();
        let m = self.meter;
        if m.force_evals > 0 || m.forces > Duration::ZERO {
            self.timings.add("forces", m.forces);
        }
        if m.solve > Duration::ZERO {
            self.timings.add("solve", m.solve);
        }
        self.timings
            .add("integrate", total.saturating_sub(m.forces + m.solve));
        result
    }
}

impl StepBackend for CpuStepper {
    fn name(&self) -> &'static str {
        "cpu"
    }

    fn configure(&mut self, model: &ClothModel, params: &SimParams, effects: &[Effect]) {
        self.forces.configure(model, params, effects);
        self.colliders = colliders_of(effects);
        if self.integrator.kind() != params.integrator {
            self.integrator = params.integrator.build();
        }
        // New strengths make whatever the integrator kept or derived stale.
        self.integrator.forces_changed();
        self.solver = params.solver;
        self.dt = params.dt;
        self.offset = params.collision_offset;
        self.divergence_speed = params.divergence_speed;
        let requested = params.substeps.max(1);
        if requested != self.requested {
            self.requested = requested;
            self.substeps = requested;
        }
    }

    fn invalidate(&mut self) {
        self.integrator.invalidate();
    }

    fn substep(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<StepReport, StepError> {
        let h = self.substep_length();
        let report = self.integrate(model, state, h)?;
        self.stats.record(&report);
        if !self.colliders.is_empty() {
            let (colliders, offset) = (&self.colliders, self.offset);
            let contacts = self.timings.time("collide", || {
                colliders
                    .iter()
                    .map(|c| c.resolve(model, state, offset))
                    .sum::<usize>()
            });
            if contacts > 0 {
                // Contacts changed positions and velocities after the integrator's step.
                self.integrator.invalidate();
            }
        }
        Ok(report)
    }

    /// If a try ends non-finite or faster than the divergence speed, or its solve fails,
    /// the state is rolled back and the frame redone with twice the substeps, up to
    /// [`MAX_REFINEMENTS`] times.
    fn frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<FrameOutcome, Diverged> {
        self.backup.clone_from(state);
        let first = self.substeps;
        for attempt in 0..=MAX_REFINEMENTS {
            let stepped = (0..self.substeps).try_for_each(|_| self.substep(model, state).map(drop));
            if stepped.is_ok() && state.is_finite() && state.max_speed() <= self.divergence_speed {
                return Ok(if attempt == 0 {
                    FrameOutcome::Stepped
                } else {
                    FrameOutcome::Refined {
                        from: first,
                        to: self.substeps,
                    }
                });
            }
            state.clone_from(&self.backup);
            // What the integrator kept belongs to the discarded attempt.
            self.integrator.invalidate();
            if attempt < MAX_REFINEMENTS {
                self.substeps *= 2;
            }
        }
        let failed = self.substeps;
        self.substeps = first;
        Err(Diverged {
            time: state.time,
            substeps: failed,
        })
    }

    fn substeps(&self) -> u32 {
        self.substeps
    }

    fn substep_length(&self) -> f32 {
        self.dt / self.substeps as f32
    }

    fn take_timings(&mut self) -> PhaseTimings {
        self.timings.take()
    }

    fn take_stats(&mut self) -> StepStats {
        std::mem::take(&mut self.stats)
    }
}
