//! Headless runs and their summary, as `clothsim simulate --json` prints it.

use std::collections::BTreeMap;
use std::time::Instant;

use crate::mesh::SpringKind;
use crate::sim::{FrameOutcome, GuardEvent, Intersections, min_surface_distance};

use super::simulation::Simulation;

/// A headless run's result.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RunSummary {
    pub scene: String,
    pub cloth: String,
    pub integrator: String,
    pub backend: String,
    pub particles: usize,
    /// Unique edges of the triangulated mesh.
    pub edges: usize,
    /// All springs (structural + shear + bend).
    pub springs: usize,
    pub structural: usize,
    pub shear: usize,
    pub bend: usize,
    pub simulated_seconds: f64,
    pub frames: u64,
    pub dt: f32,
    /// Substeps per frame in effect at the end of the run (the guard may have raised them).
    pub substeps: u32,
    /// Substeps per frame the parameters ask for.
    pub requested_substeps: u32,
    pub finite: bool,
    /// m/s.
    pub max_speed: f32,
    /// Smallest signed particle-to-surface distance, metres; null without colliders.
    pub min_collider_distance: Option<f32>,
    /// Joules.
    pub kinetic_energy: f64,
    pub wall_seconds: f64,
    /// Frames the guard had to redo (with more substeps or the fallback integrator).
    pub refined_frames: u64,
    /// The integrator in effect at the end (the guard's fallback may have replaced the
    /// requested one).
    pub integrator_in_effect: String,
    /// Everything the stability guard did, in order.
    pub guard_events: Vec<GuardEvent>,
    /// Wall time and calls of every phase that ran during the run (only those), and
    /// self-contact's setup for the cloth ([`crate::sim::SELF_SETUP`]) where it was made
    /// since the last run (with the simulation, or for a new cloth): not in the run's wall
    /// time.
    pub phases: BTreeMap<String, PhaseSummary>,
    /// Linear-solver (conjugate-gradient) iterations per step during the run: 0 for
    /// integrators without a linear solve.
    pub solver_iterations_per_step: f64,
    /// The largest intersection counts seen after any frame, when asked for (`simulate
    /// --check-intersections`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intersections: Option<Intersections>,
    /// With self-collision: the pairs of the cloth that prescribed motion (pins, handles,
    /// a grab) drove together where no cut could keep them apart, since the simulation
    /// began, in the substeps that stand (not those of the tries the stability guard threw
    /// away); 0 when the guarantee held everywhere.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub forced_pairs: Option<u64>,
    /// Set when the run stopped early because it diverged.
    pub error: Option<String>,
    /// What [`Simulation::warnings`] says about the cloth and the scene's start (the
    /// import's notes, a cloth that starts through itself or a solid); left out where
    /// there is none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// One phase of a run.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PhaseSummary {
    pub calls: u64,
    pub seconds: f64,
}

impl Simulation {
    /// Runs headless for `seconds` of simulated time (whole frames) and summarises.
    pub fn run(&mut self, seconds: f64) -> RunSummary {
        let run = self.run_observed(seconds, |_, _| Ok::<(), std::convert::Infallible>(()));
        run.unwrap_or_else(|never| match never {})
    }

    /// As [`Simulation::run`], calling `observe` with the simulation and the frame's number
    /// before the first frame (0) and after each (its wall time counts in the run's).
    ///
    /// # Errors
    /// The first error `observe` returns; the run stops there.
    pub fn run_observed<E>(
        &mut self,
        seconds: f64,
        mut observe: impl FnMut(&Simulation, u64) -> Result<(), E>,
    ) -> Result<RunSummary, E> {
        let frames = (seconds / self.params().step.dt as f64).round().max(0.0) as u64;
        // Timings and counts gathered before the run are not the run's, but for
        // self-contact's setup (made with the simulation), listed beside them.
        let before = self.take_timings();
        self.take_stats();
        let start = Instant::now();
        let mut refined = 0;
        let mut error = None;
        let mut events = Vec::new();
        observe(self, 0)?;
        for frame in 1..=frames {
            let outcome = self.step_frame();
            events.extend(self.take_guard_events());
            if outcome.is_ok() {
                observe(self, frame)?;
            }
            match outcome {
                Ok(FrameOutcome::Stepped | FrameOutcome::Recovered { .. }) => {}
                Ok(FrameOutcome::Refined { .. } | FrameOutcome::FellBack { .. }) => refined += 1,
                Err(e) => {
                    error = Some(e.to_string());
                    break;
                }
            }
        }
        let mut summary = self.summary(start.elapsed().as_secs_f64());
        let mut timings = self.take_timings();
        if let Some(setup) = before.get(crate::sim::SELF_SETUP) {
            timings.add_calls(setup.name, setup.time, setup.calls);
        }
        summary.phases = timings
            .phases()
            .iter()
            .map(|p| {
                let s = PhaseSummary {
                    calls: p.calls,
                    seconds: p.time.as_secs_f64(),
                };
                (p.name.to_string(), s)
            })
            .collect();
        summary.solver_iterations_per_step = self.take_stats().solver_iterations_per_step();
        summary.refined_frames = refined;
        summary.guard_events = events;
        summary.error = error;
        Ok(summary)
    }

    /// The current state's summary; `wall_seconds` as given.
    pub fn summary(&self, wall_seconds: f64) -> RunSummary {
        let model = self.model();
        let state = self.state();
        let count = |k| model.springs.count(k);
        RunSummary {
            scene: self.scenario().to_string(),
            cloth: self.cloth_name().to_string(),
            integrator: self.params().step.integrator.name().to_string(),
            backend: self.backend_name().to_string(),
            particles: model.particle_count(),
            edges: model.mesh_edges,
            springs: model.springs.len(),
            structural: count(SpringKind::Structural),
            shear: count(SpringKind::Shear),
            bend: count(SpringKind::Bend),
            simulated_seconds: state.time,
            frames: self.frames(),
            dt: self.params().step.dt,
            substeps: self.substeps(),
            requested_substeps: self.params().step.substeps,
            finite: state.is_finite(),
            max_speed: state.max_speed(),
            min_collider_distance: min_surface_distance(self.effects(), &state.pos, state.time),
            kinetic_energy: state.kinetic_energy(model),
            wall_seconds,
            refined_frames: 0,
            integrator_in_effect: self.integrator_in_effect().name().to_string(),
            guard_events: Vec::new(),
            phases: BTreeMap::new(),
            solver_iterations_per_step: 0.0,
            intersections: None,
            forced_pairs: self.forced_pairs(),
            error: None,
            warnings: self.warnings().to_vec(),
        }
    }
}
