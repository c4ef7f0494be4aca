//! The self-contact benchmark behind `clothsim bench --crumple`: the built-in `crumple`
//! scene (a cloth dropped from 2 m onto a small sphere, folding onto the ground) at a grid
//! size, timed over its first simulated second: the wall per simulated second, the contact
//! phases per substep against the spring forces of the same substeps, and the pairs the
//! search keeps per particle.

use std::time::Duration;

use serde::Serialize;

use crate::bench_contact::ContactBenchError;
use crate::mesh::ImportOptions;
use crate::scene::{Scene, Simulation};
use crate::sim::IntegratorKind;

/// The simulated seconds timed.
pub const CRUMPLE_SECONDS: f64 = 1.0;

/// One row of the crumple bench.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CrumpleRow {
    /// Quads along each side of the cloth.
    pub quads: u32,
    pub particles: usize,
    pub integrator: String,
    /// CPU threads the solver may share a step among.
    pub threads: usize,
    pub substeps: u64,
    /// Wall seconds per simulated second (1 or less: real time).
    pub wall_per_second: f64,
    /// Self-contact (its pass and its recheck after the solids) and the solids, per
    /// substep, µs.
    pub contact_us: f64,
    /// Self-contact's setup for the cloth (once, when the simulation is made), ms: not in
    /// [`CrumpleRow::contact_us`].
    pub setup_ms: f64,
    /// The spring forces per substep, µs (0 for an integrator without them: XPBD's
    /// constraints stand in their place).
    pub springs_us: f64,
    /// Pairs the search kept per particle, averaged over the last substep of each frame.
    pub pairs_per_particle: f64,
    /// Searches of the whole tree per substep (sampled as the pairs are).
    pub searches_per_substep: f64,
    /// Searches of only the triangles whose particles left their boxes, per substep
    /// (sampled as the pairs are); substeps with neither reused the pairs found before.
    pub refreshes_per_substep: f64,
    /// Pairs prescribed motion forced, over the run (0: nothing was forced).
    pub forced: u64,
}

/// Runs `crumple` at `quads` quads a side under `integrator` (the scene's own with `None`)
/// for [`CRUMPLE_SECONDS`] on the current thread pool, and times it.
///
/// # Errors
/// The scene cannot be built at that size, or a frame diverged.
pub fn crumple_one(
    quads: u32,
    integrator: Option<IntegratorKind>,
) -> Result<CrumpleRow, ContactBenchError> {
    let mut scene = Scene::open_resized("crumple", None, &ImportOptions::default(), Some(quads))?;
    if let Some(k) = integrator {
        scene.params.step.integrator = k;
    }
    let mut sim = Simulation::new(scene);
    // Self-contact's setup, made with the simulation: reported on its own.
    let setup = sim.take_timings().totals(crate::sim::SELF_SETUP).0;
    let frames = (CRUMPLE_SECONDS / f64::from(sim.params().step.dt)).round() as u32;
    // Sampled at the last substep of each frame.
    let (mut searches, mut refreshes, mut pairs, mut sampled) = (0u64, 0u64, 0u64, 0u64);
    let start = std::time::Instant::now();
    for _ in 0..frames {
        sim.step_frame()?;
        if let Some(work) = sim.self_collision_work() {
            searches += work.searches;
            refreshes += work.refreshes;
            pairs += work.candidates;
            sampled += 1;
        }
    }
    let wall = start.elapsed().as_secs_f64();
    let timings = sim.take_timings();
    let phase = |name| timings.totals(name);
    // Every substep resolves self-contact once (XPBD has no spring-force phase).
    let (springs, substeps) = (phase("springs").0, phase("self-collision").1);
    let contact: Duration = ["self-collision", "self-recheck", "sphere", "plane"]
        .iter()
        .map(|&name| phase(name).0)
        .sum();
    let per = |t: Duration| t.as_secs_f64() * 1e6 / substeps.max(1) as f64;
    let particles = sim.model().particle_count();
    let work = sim.self_collision_work().unwrap_or_default();
    Ok(CrumpleRow {
        quads,
        particles,
        integrator: sim.integrator_in_effect().name().to_string(),
        threads: crate::parallel::Team::current().members(),
        substeps,
        wall_per_second: wall / sim.state().time.max(f64::EPSILON),
        contact_us: per(contact),
        setup_ms: setup.as_secs_f64() * 1e3,
        springs_us: per(springs),
        pairs_per_particle: pairs as f64 / sampled.max(1) as f64 / particles as f64,
        searches_per_substep: searches as f64 / sampled.max(1) as f64,
        refreshes_per_substep: refreshes as f64 / sampled.max(1) as f64,
        forced: work.forced_total,
    })
}
