//! A running simulation: a scene, its current state and the stepper built from its effects.
//! The GUI, the CLI and the tests all drive this one type.

use std::time::Instant;

use crate::cloth::ClothState;
use crate::sim::{Diverged, FrameOutcome, PhaseTimings, Stepper};

use super::scene::Scene;

/// Scene + live state + stepper.
pub struct Simulation {
    pub scene: Scene,
    pub state: ClothState,
    stepper: Stepper,
    /// Frames advanced since the last reset.
    pub frames: u64,
}

/// A headless run's result, as `clothsim simulate --json` prints it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RunSummary {
    pub scene: String,
    pub cloth: String,
    pub integrator: String,
    pub particles: usize,
    /// Mesh edges (structural + shear springs).
    pub springs: usize,
    pub bend_pairs: usize,
    pub simulated_seconds: f64,
    pub frames: u64,
    pub dt: f32,
    /// Substeps per frame at the end of the run (the guard may have raised them).
    pub substeps: u32,
    pub finite: bool,
    /// m/s.
    pub max_speed: f32,
    /// Smallest signed particle-to-surface distance, metres; null without colliders.
    pub min_collider_distance: Option<f32>,
    /// Joules.
    pub kinetic_energy: f64,
    pub wall_seconds: f64,
    /// Frames the guard had to redo with more substeps.
    pub refined_frames: u64,
    /// Set when the run stopped early because it diverged.
    pub error: Option<String>,
}

impl Simulation {
    /// Starts the scene from its initial state.
    pub fn new(scene: Scene) -> Self {
        let stepper = Stepper::new(&scene.params, &scene.effects);
        Self {
            state: scene.initial.clone(),
            scene,
            stepper,
            frames: 0,
        }
    }

    /// Back to the initial state (parameters kept).
    pub fn reset(&mut self) {
        self.state.clone_from(&self.scene.initial);
        self.frames = 0;
        self.rebuild_stepper();
    }

    /// Rebuilds the stepper after the scene's parameters or effects changed; the state is
    /// kept, so changes apply live.
    pub fn rebuild_stepper(&mut self) {
        self.stepper = Stepper::new(&self.scene.params, &self.scene.effects);
    }

    pub fn stepper(&self) -> &Stepper {
        &self.stepper
    }

    /// Advances one frame (`params.dt`).
    ///
    /// # Errors
    /// [`Diverged`]: the state is left at the frame's start.
    pub fn step_frame(&mut self) -> Result<FrameOutcome, Diverged> {
        let out = self.stepper.frame(&self.scene.model, &mut self.state)?;
        self.frames += 1;
        Ok(out)
    }

    /// Advances one substep (`dt / substeps`) with no divergence guard; for tests and
    /// tools that inspect every substep.
    pub fn substep(&mut self) {
        self.stepper.substep(&self.scene.model, &mut self.state);
    }

    /// Timings since the last call, by phase.
    pub fn take_timings(&mut self) -> PhaseTimings {
        self.stepper.take_timings()
    }

    /// Runs headless for `seconds` of simulated time (whole frames) and summarises.
    pub fn run(&mut self, seconds: f64) -> RunSummary {
        let frames = (seconds / self.scene.params.dt as f64).round().max(0.0) as u64;
        let start = Instant::now();
        let mut refined = 0;
        let mut error = None;
        for _ in 0..frames {
            match self.step_frame() {
                Ok(FrameOutcome::Stepped) => {}
                Ok(FrameOutcome::Refined { .. }) => refined += 1,
                Err(e) => {
                    error = Some(e.to_string());
                    break;
                }
            }
        }
        let wall = start.elapsed().as_secs_f64();
        let mut summary = self.summary(wall);
        summary.refined_frames = refined;
        summary.error = error;
        summary
    }

    /// The current state's summary; `wall_seconds` as given.
    pub fn summary(&self, wall_seconds: f64) -> RunSummary {
        let model = &self.scene.model;
        RunSummary {
            scene: self.scene.scenario.to_string(),
            cloth: self.scene.cloth_name.clone(),
            integrator: self.scene.params.integrator.name().to_string(),
            particles: model.particle_count(),
            springs: model.edge_count(),
            bend_pairs: model.springs.count(crate::mesh::SpringKind::Bend),
            simulated_seconds: self.state.time,
            frames: self.frames,
            dt: self.scene.params.dt,
            substeps: self.stepper.substeps(),
            finite: self.state.is_finite(),
            max_speed: self.state.max_speed(),
            min_collider_distance: self.stepper.min_collider_distance(&self.state),
            kinetic_energy: self.state.kinetic_energy(model),
            wall_seconds,
            refined_frames: 0,
            error: None,
        }
    }
}
