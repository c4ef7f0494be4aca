//! One measured run: an integrator at one step, sampled along its trajectory.

use std::time::Instant;

use glam::Vec3;

use crate::scene::{Scene, Simulation};
use crate::sim::{Effect, IntegratorKind, StepStats};

/// Speed (m/s) past which a run is stopped and counted as unstable: a hundred times any
/// speed in the scenes, so only a blow-up gets there.
pub const BLOW_UP_SPEED: f32 = 1.0e4;

/// What a run keeps at each sample time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Record {
    /// Particle positions (for errors against a reference).
    Positions,
    /// Total mechanical energy and kinetic energy (for drift and stability).
    Energy,
}

/// A run of `seconds` split into equal sample intervals, each of whole steps.
#[derive(Clone, Debug)]
pub struct Trajectory {
    pub integrator: IntegratorKind,
    /// The step actually taken, seconds (the requested one, adjusted so that whole steps
    /// fill each sample interval).
    pub h: f64,
    /// Steps per sample interval.
    pub steps_per_sample: u32,
    /// Steps taken in all.
    pub steps: u64,
    /// Positions at each sample time (with [`Record::Positions`]).
    pub positions: Vec<Vec<Vec3>>,
    /// Total energy at t = 0 and each sample time, joules (with [`Record::Energy`]).
    pub energy: Vec<f64>,
    /// Kinetic energy at each sample time, joules (with [`Record::Energy`]).
    pub kinetic: Vec<f64>,
    /// False when the state went non-finite, a solve failed, or it blew up.
    pub finite: bool,
    /// Wall time of the stepping alone, seconds.
    pub wall: f64,
    pub stats: StepStats,
}

impl Trajectory {
    /// Largest deviation of the total energy from its start, joules (infinite if the run
    /// did not stay finite).
    pub fn energy_deviation(&self) -> f64 {
        if !self.finite {
            return f64::INFINITY;
        }
        let e0 = self.energy.first().copied().unwrap_or(0.0);
        self.energy
            .iter()
            .map(|e| (e - e0).abs())
            .fold(0.0, f64::max)
    }

    /// Largest gain of the total energy over its start, joules (0 if it only ever fell;
    /// infinite if the run did not stay finite). Dissipation is no instability: only this
    /// counts for stability.
    pub fn energy_growth(&self) -> f64 {
        if !self.finite {
            return f64::INFINITY;
        }
        let e0 = self.energy.first().copied().unwrap_or(0.0);
        self.energy.iter().map(|e| e - e0).fold(0.0, f64::max)
    }

    /// Largest kinetic energy seen, joules.
    pub fn peak_kinetic(&self) -> f64 {
        self.kinetic.iter().copied().fold(0.0, f64::max)
    }
}

/// The scene without its dissipation: no air damping, no spring dashpots (contacts, being
/// inelastic, stay).
pub fn undamped(scene: &Scene) -> Scene {
    let mut scene = scene.clone();
    scene.params.material.damping = [0.0; 3];
    scene
        .effects
        .retain(|e| !matches!(e, Effect::AirDamping(_)));
    scene
}

/// Runs `scene` with `integrator` at a step near `h` for `seconds`, recording at
/// `samples` equally spaced times. No stability guard: the step is what was asked for.
pub fn run(
    scene: &Scene,
    integrator: IntegratorKind,
    h: f64,
    seconds: f64,
    samples: u32,
    record: Record,
) -> Trajectory {
    let samples = samples.max(1);
    let interval = seconds / samples as f64;
    let steps_per_sample = (interval / h).round().clamp(1.0, u32::MAX as f64) as u32;
    let mut scene = scene.clone();
    scene.params.step.integrator = integrator;
    scene.params.step.dt = interval as f32;
    scene.params.step.substeps = steps_per_sample;
    let mut sim = Simulation::new(scene);
    let mut out = Trajectory {
        integrator,
        h: interval / steps_per_sample as f64,
        steps_per_sample,
        steps: 0,
        positions: Vec::new(),
        energy: Vec::new(),
        kinetic: Vec::new(),
        finite: true,
        wall: 0.0,
        stats: StepStats::default(),
    };
    if record == Record::Energy {
        out.energy.push(sim.energy());
    }
    'samples: for _ in 0..samples {
        let start = Instant::now();
        for _ in 0..steps_per_sample {
            out.steps += 1;
            if sim.substep().is_err() {
                out.finite = false;
                break;
            }
        }
        out.wall += start.elapsed().as_secs_f64();
        let state = sim.state();
        if !out.finite || !state.is_finite() || state.max_speed() > BLOW_UP_SPEED {
            out.finite = false;
            break 'samples;
        }
        match record {
            Record::Positions => out.positions.push(state.pos.clone()),
            Record::Energy => {
                out.energy.push(sim.energy());
                out.kinetic.push(state.kinetic_energy(sim.model()));
            }
        }
    }
    out.stats = sim.take_stats();
    out
}

/// Position error of `run` against `reference` sampled at the same times: the largest over
/// the samples of the RMS and of the maximum over particles, metres. Infinite when the run
/// did not finish.
pub fn position_error(run: &Trajectory, reference: &Trajectory) -> (f64, f64) {
    if !run.finite || run.positions.len() != reference.positions.len() {
        return (f64::INFINITY, f64::INFINITY);
    }
    let (mut rms, mut max) = (0.0f64, 0.0f64);
    for (x, r) in run.positions.iter().zip(&reference.positions) {
        let mut sum = 0.0f64;
        for (a, b) in x.iter().zip(r) {
            let d = a.distance(*b) as f64;
            sum += d * d;
            max = max.max(d);
        }
        rms = rms.max((sum / x.len().max(1) as f64).sqrt());
    }
    (rms, max)
}
