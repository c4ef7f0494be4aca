//! The stepper: integrator + the scene's forces + its colliders, advanced in fixed substeps,
//! with a guard that rolls back a diverging frame and retries it with more substeps.

use crate::cloth::{ClothModel, ClothState};

use super::collider::{Collider, min_collider_distance};
use super::effect::Effect;
use super::forces::{Force, ForceSet};
use super::integrator::{Integrator, StepContext};
use super::params::SimParams;
use super::timings::PhaseTimings;

/// How many times a diverging frame is retried, each time with twice the substeps.
const MAX_REFINEMENTS: u32 = 3;

/// A frame that could not be made stable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "simulation diverged at t = {time:.3} s even with {substeps} substeps per frame; \
     the state was rolled back to the last good frame. Lower the stiffness or the time step."
)]
pub struct Diverged {
    pub time: f64,
    pub substeps: u32,
}

/// What happened in a frame that succeeded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameOutcome {
    /// Advanced normally.
    Stepped,
    /// The first try diverged; the frame was redone with more substeps, which now stay.
    Refined { from: u32, to: u32 },
}

/// Advances a cloth through time. Built from a scene's effect list: absent effects are not
/// in it and cost nothing.
pub struct Stepper {
    integrator: Box<dyn Integrator>,
    forces: ForceSet,
    colliders: Vec<Collider>,
    dt: f32,
    substeps: u32,
    offset: f32,
    divergence_speed: f32,
    timings: PhaseTimings,
    /// The frame's start state, restored when a try diverges.
    backup: ClothState,
}

impl Stepper {
    /// Builds the stepper for `effects` with the strengths in `params`.
    pub fn new(params: &SimParams, effects: &[Effect]) -> Self {
        let mut forces = Vec::new();
        let mut colliders = Vec::new();
        for e in effects {
            match e {
                Effect::Gravity => forces.push(Force::Gravity(params.gravity)),
                Effect::Springs => forces.push(Force::Springs {
                    stiffness: params.stiffness,
                    damping: params.damping,
                }),
                Effect::AirDamping => forces.push(Force::AirDamping(params.air_damping)),
                Effect::Collider(c) => colliders.push(*c),
            }
        }
        Self {
            integrator: params.integrator.build(),
            forces: ForceSet { forces },
            colliders,
            dt: params.dt,
            substeps: params.substeps.max(1),
            offset: params.collision_offset,
            divergence_speed: params.divergence_speed,
            timings: PhaseTimings::default(),
            backup: ClothState::default(),
        }
    }

    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// Substeps per frame currently in use (the guard may have raised it).
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// Substep length, seconds.
    pub fn h(&self) -> f32 {
        self.dt / self.substeps as f32
    }

    /// One substep: integrate, then resolve every collider.
    pub fn substep(&mut self, model: &ClothModel, state: &mut ClothState) {
        let h = self.h();
        let mut ctx = StepContext {
            model,
            forces: &self.forces,
            timings: &mut self.timings,
        };
        self.integrator.step(&mut ctx, state, h);
        if !self.colliders.is_empty() {
            let (colliders, offset) = (&self.colliders, self.offset);
            self.timings.time("collide", || {
                for c in colliders {
                    c.resolve(model, state, offset, h);
                }
            });
        }
    }

    /// One frame of `dt` seconds. If it ends non-finite or faster than the divergence speed,
    /// the state is rolled back and the frame redone with twice the substeps, up to
    /// three times.
    ///
    /// # Errors
    /// [`Diverged`] when even the finest try failed; `state` is then the frame's start state.
    pub fn frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<FrameOutcome, Diverged> {
        self.backup.clone_from(state);
        let first = self.substeps;
        for attempt in 0..=MAX_REFINEMENTS {
            for _ in 0..self.substeps {
                self.substep(model, state);
            }
            if state.is_finite() && state.max_speed() <= self.divergence_speed {
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
            // A fresh integrator: its kept values belong to the discarded attempt.
            self.integrator = self.integrator.kind().build();
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

    /// Timings since the last call, by phase; resets them.
    pub fn take_timings(&mut self) -> PhaseTimings {
        self.timings.take()
    }

    /// Smallest signed particle–collider distance, metres; `None` without colliders.
    pub fn min_collider_distance(&self, state: &ClothState) -> Option<f32> {
        min_collider_distance(&self.colliders, &state.pos)
    }
}
