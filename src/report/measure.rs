//! One measured run: an integrator at one step, sampled along its trajectory.

use std::time::Instant;

use glam::{DVec3, Vec3};

use crate::scene::{Scene, Simulation};
use crate::sim::{Effect, IntegratorKind, StepStats, intersections, min_surface_distance};

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

/// What a run's contacts let through.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ContactMeasures {
    /// Deepest penetration of a particle into a sphere or plane, metres (0: none).
    pub deepest_penetration: f64,
    /// Most intersecting triangle pairs (the cloth's own, and against each solid) at one
    /// sample time.
    pub intersections: usize,
}

impl ContactMeasures {
    /// The measures of the cloth at `pos` among `effects` at time `t`, or `None` when the
    /// scene has nothing to pass through (no solid, no self-collision).
    pub fn of(effects: &[Effect], triangles: &[[u32; 3]], pos: &[Vec3], t: f64) -> Option<Self> {
        let contact = |e: &Effect| e.is_solid() || matches!(e, Effect::SelfCollision(_));
        if !effects.iter().any(contact) {
            return None;
        }
        let inside = min_surface_distance(effects, pos, t).map_or(0.0, |d| (-d).max(0.0));
        Some(Self {
            deepest_penetration: inside as f64,
            intersections: intersections(effects, t, triangles, pos).total(),
        })
    }

    /// The worse of two.
    fn worst(self, other: Self) -> Self {
        Self {
            deepest_penetration: self.deepest_penetration.max(other.deepest_penetration),
            intersections: self.intersections.max(other.intersections),
        }
    }
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
    /// Positions at each sample time (with [`Record::Positions`]), in the precision the run
    /// computed in.
    pub positions: Vec<Vec<DVec3>>,
    /// Total energy at t = 0 and each sample time, joules (with [`Record::Energy`]).
    pub energy: Vec<f64>,
    /// Kinetic energy at each sample time, joules (with [`Record::Energy`]).
    pub kinetic: Vec<f64>,
    /// False when the state went non-finite, a solve failed, or it blew up.
    pub finite: bool,
    /// On a scene with solids or self-collision (with [`Record::Positions`]): the deepest
    /// any particle was inside a sphere or plane at a sample time (metres, 0 when none was),
    /// and the most intersecting triangle pairs at one ([`crate::sim::intersections()`]).
    pub contact: Option<ContactMeasures>,
    /// Wall time of the stepping alone, seconds.
    pub wall: f64,
    pub stats: StepStats,
}

impl Trajectory {
    /// A run of `integrator` that has not started: no steps, no samples, finite.
    pub fn empty(integrator: IntegratorKind) -> Self {
        Self {
            integrator,
            h: 0.0,
            steps_per_sample: 0,
            steps: 0,
            positions: Vec::new(),
            energy: Vec::new(),
            kinetic: Vec::new(),
            finite: true,
            contact: None,
            wall: 0.0,
            stats: StepStats::default(),
        }
    }

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
        h: interval / steps_per_sample as f64,
        steps_per_sample,
        ..Trajectory::empty(integrator)
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
            Record::Positions => {
                let now = ContactMeasures::of(
                    sim.effects(),
                    &sim.model().triangles,
                    &state.pos,
                    state.time,
                );
                out.contact = match (out.contact, now) {
                    (Some(a), Some(b)) => Some(a.worst(b)),
                    (a, b) => a.or(b),
                };
                out.positions.push(sim.positions_f64());
            }
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
            let d = a.distance(*b);
            sum += d * d;
            max = max.max(d);
        }
        rms = rms.max((sum / x.len().max(1) as f64).sqrt());
    }
    (rms, max)
}
