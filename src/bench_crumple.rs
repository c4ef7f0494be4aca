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
use crate::sim::effects::EffectKind;
use crate::sim::{
    BETWEEN_SOLIDS, CONTACT_START, ClothSprings, GuardAction, IntegratorKind, PhaseTimings, Plane,
    SELF_RECHECK, SELF_UPKEEP, SelfCollision, Sphere,
};

/// The simulated seconds timed.
pub const CRUMPLE_SECONDS: f64 = 1.0;

/// The grid the speed targets are set at: quads along each side of the cloth.
pub const TARGET_QUADS: u32 = 64;

/// The contact phases a substep at [`TARGET_QUADS`] at most this many times the spring
/// forces of the same substeps.
pub const CONTACT_TARGET: f64 = 10.0;

/// The threads on which [`TARGET_QUADS`] should run in real time (at most a second of
/// wall a simulated second).
pub const REAL_TIME_THREADS: usize = 2;

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
    /// The contact phases' time over the springs' in the same substeps (0 without
    /// springs).
    pub contact_per_springs: f64,
    /// Self-contact alone (its pass and its recheck), per substep, µs: the contact phases
    /// less the solids'.
    pub self_contact_us: f64,
    /// Self-contact's time over the springs' in the same substeps (0 without springs): the
    /// measure of the 70–77× self-collision cost before its tree (docs/performance.md,
    /// "Self-contact").
    pub self_per_springs: f64,
    /// The runs the row's times are the medians of ([`median_row`]); 1 for one run.
    pub runs: usize,
    /// Pairs the search kept per particle, averaged over the last substep of each frame.
    pub pairs_per_particle: f64,
    /// Searches of the whole tree per substep (sampled as the pairs are).
    pub searches_per_substep: f64,
    /// Searches of only the triangles whose particles left their boxes, per substep
    /// (sampled as the pairs are); substeps with neither reused the pairs found before.
    pub refreshes_per_substep: f64,
    /// Pairs prescribed motion forced, over the run (0: nothing was forced).
    pub forced: u64,
    /// The integrator the stability guard fell back to during the run, where it did: the
    /// row's substeps are then partly that one's (`integrator` is the one asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fell_back_to: Option<String>,
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
    // Every substep resolves self-contact once (XPBD has no spring-force phase).
    let substeps = timings.totals(SelfCollision::NAME).1;
    let [springs, own, contact] = phase_times(&timings);
    let over_springs = |t: Duration| {
        if springs.is_zero() {
            0.0
        } else {
            t.as_secs_f64() / springs.as_secs_f64()
        }
    };
    let per = |t: Duration| t.as_secs_f64() * 1e6 / substeps.max(1) as f64;
    let particles = sim.model().particle_count();
    let fell_back_to = (sim.take_guard_events().iter()).find_map(|e| match e.action {
        GuardAction::FellBack { integrator } => Some(integrator.name().to_string()),
        _ => None,
    });
    Ok(CrumpleRow {
        quads,
        particles,
        integrator: sim.params().step.integrator.name().to_string(),
        threads: crate::parallel::Team::current().members(),
        substeps,
        wall_per_second: wall / sim.state().time.max(f64::EPSILON),
        contact_us: per(contact),
        setup_ms: setup.as_secs_f64() * 1e3,
        springs_us: per(springs),
        contact_per_springs: over_springs(contact),
        self_contact_us: per(own),
        self_per_springs: over_springs(own),
        runs: 1,
        pairs_per_particle: pairs as f64 / sampled.max(1) as f64 / particles as f64,
        searches_per_substep: searches as f64 / sampled.max(1) as f64,
        refreshes_per_substep: refreshes as f64 / sampled.max(1) as f64,
        forced: sim.forced_pairs().unwrap_or(0),
        fell_back_to,
    })
}

/// The springs' time, self-contact's (its pass, its recheck and its upkeep between the
/// effects) and the contact phases' (self-contact's, the solids' (`crumple`'s sphere and
/// ground, and what settles a particle left between them) and the copy of each substep's
/// start their paths run from), from a run's timings.
fn phase_times(timings: &PhaseTimings) -> [Duration; 3] {
    let time = |name: &str| timings.totals(name).0;
    let own = time(SelfCollision::NAME) + time(SELF_RECHECK) + time(SELF_UPKEEP);
    [
        time(ClothSprings::NAME),
        own,
        own + time(Sphere::NAME) + time(Plane::NAME) + time(CONTACT_START) + time(BETWEEN_SOLIDS),
    ]
}

impl CrumpleRow {
    /// What the row reached beside the speed targets, where they are set for it (at
    /// [`TARGET_QUADS`]): its contact phases over the springs against [`CONTACT_TARGET`]
    /// (where it has springs to compare with), and on [`REAL_TIME_THREADS`] its wall a
    /// simulated second against real time; each said met or not.
    pub fn beside_targets(&self) -> Option<String> {
        if self.quads != TARGET_QUADS {
            return None;
        }
        let met = |yes: bool| if yes { "met" } else { "not met" };
        let contact = if self.springs_us > 0.0 {
            format!(
                "contact {:.1}× the springs (at most {CONTACT_TARGET}×: {})",
                self.contact_per_springs,
                met(self.contact_per_springs <= CONTACT_TARGET)
            )
        } else {
            "no spring forces to set the contact against".to_string()
        };
        let wall = (self.threads == REAL_TIME_THREADS).then(|| {
            format!(
                "; {:.2} s of wall a simulated second (at most 1 on {REAL_TIME_THREADS} threads: {})",
                self.wall_per_second,
                met(self.wall_per_second <= 1.0)
            )
        });
        Some(format!(
            "beside the targets at {TARGET_QUADS}²: {contact}{}",
            wall.unwrap_or_default()
        ))
    }
}

/// One row for several runs of the same: each time, and the ratio of the contact phases to
/// the springs, the runs' median (of an even count, the mean of the middle two); the
/// counts as the first run's (the same in every run: a run's pairs and searches do not
/// depend on its timing). A bench on a shared machine swings from run to run with the
/// machine's load, the springs' few microseconds a substep most. `None` for no run.
pub fn median_row(runs: &[CrumpleRow]) -> Option<CrumpleRow> {
    let first = runs.first()?;
    let median = |field: fn(&CrumpleRow) -> f64| {
        let mut x: Vec<f64> = runs.iter().map(field).collect();
        x.sort_by(f64::total_cmp);
        let n = x.len();
        0.5 * (x[(n - 1) / 2] + x[n / 2])
    };
    Some(CrumpleRow {
        wall_per_second: median(|r| r.wall_per_second),
        contact_us: median(|r| r.contact_us),
        setup_ms: median(|r| r.setup_ms),
        springs_us: median(|r| r.springs_us),
        contact_per_springs: median(|r| r.contact_per_springs),
        self_contact_us: median(|r| r.self_contact_us),
        self_per_springs: median(|r| r.self_per_springs),
        runs: runs.len(),
        ..first.clone()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(contact_us: f64, springs_us: f64) -> CrumpleRow {
        CrumpleRow {
            quads: 8,
            particles: 81,
            integrator: "implicit-euler".into(),
            threads: 2,
            substeps: 240,
            wall_per_second: contact_us / 100.0,
            contact_us,
            setup_ms: 1.0,
            springs_us,
            contact_per_springs: contact_us / springs_us,
            self_contact_us: 0.8 * contact_us,
            self_per_springs: 0.8 * contact_us / springs_us,
            pairs_per_particle: 0.5,
            searches_per_substep: 0.1,
            refreshes_per_substep: 0.2,
            forced: 0,
            fell_back_to: None,
            runs: 1,
        }
    }

    /// The contact phases are self-contact's pass, recheck and upkeep, the solids' and the
    /// copy of the substep's start; the springs are their own phase; the other phases
    /// count in none of them.
    #[test]
    fn the_contact_phases_are_self_contacts_and_the_solids() {
        let mut timings = PhaseTimings::default();
        let ms = Duration::from_millis;
        for (name, t) in [
            ("springs", 1),
            ("self-collision", 30),
            ("self-recheck", 4),
            ("self-upkeep", 20_000),
            ("contact-start", 400_000),
            ("sphere", 200),
            ("plane", 1000),
            ("between-solids", 3_000_000),
            ("solve", 7000),
            ("self-setup", 50_000),
        ] {
            timings.add(name, ms(t));
        }
        assert_eq!(phase_times(&timings), [ms(1), ms(20_034), ms(3_421_234)]);
        assert_eq!(phase_times(&PhaseTimings::default()), [Duration::ZERO; 3]);
    }

    /// Each time is its own median, and so is the ratio: the ratio of the medians would
    /// pair one run's contact with another's springs.
    #[test]
    fn a_rows_times_are_the_medians_of_its_runs() {
        assert_eq!(median_row(&[]), None);
        let runs = [row(300.0, 30.0), row(500.0, 25.0), row(400.0, 50.0)];
        let m = median_row(&runs).unwrap();
        assert_eq!(
            (m.contact_us, m.springs_us, m.wall_per_second),
            (400.0, 30.0, 4.0)
        );
        assert_eq!((m.contact_per_springs, m.runs), (10.0, 3));
        assert_eq!((m.self_contact_us, m.self_per_springs), (320.0, 8.0));
        assert_eq!((m.quads, m.pairs_per_particle), (8, 0.5));
        let even = median_row(&runs[..2]).unwrap();
        assert_eq!((even.contact_us, even.contact_per_springs), (400.0, 15.0));
        assert_eq!(median_row(&runs[..1]), Some(runs[0].clone()));
    }

    /// A row at the targets' grid says what it reached beside each target, met or not:
    /// the contact against the springs where there are springs, the wall on two threads.
    #[test]
    fn a_row_at_the_targets_grid_says_what_it_reached_beside_them() {
        let at = |contact_us: f64, springs_us: f64, threads: usize| CrumpleRow {
            quads: TARGET_QUADS,
            threads,
            ..row(contact_us, springs_us)
        };
        assert_eq!(row(300.0, 30.0).beside_targets(), None);
        assert_eq!(
            at(450.0, 30.0, 2).beside_targets().unwrap(),
            "beside the targets at 64²: contact 15.0× the springs (at most 10×: not met); \
             4.50 s of wall a simulated second (at most 1 on 2 threads: not met)"
        );
        assert_eq!(
            at(90.0, 10.0, 2).beside_targets().unwrap(),
            "beside the targets at 64²: contact 9.0× the springs (at most 10×: met); \
             0.90 s of wall a simulated second (at most 1 on 2 threads: met)"
        );
        // Exactly at a target is within it.
        let edge = CrumpleRow {
            wall_per_second: 1.0,
            ..at(100.0, 10.0, 2)
        };
        assert!(!edge.beside_targets().unwrap().contains("not met"));
        // Real time is asked of two threads: on others the wall is not set beside it.
        for threads in [1, 4] {
            assert_eq!(
                at(90.0, 10.0, threads).beside_targets().unwrap(),
                "beside the targets at 64²: contact 9.0× the springs (at most 10×: met)"
            );
        }
        let xpbd = CrumpleRow {
            springs_us: 0.0,
            contact_per_springs: 0.0,
            ..at(90.0, 10.0, 1)
        };
        assert_eq!(
            xpbd.beside_targets().unwrap(),
            "beside the targets at 64²: no spring forces to set the contact against"
        );
    }
}
