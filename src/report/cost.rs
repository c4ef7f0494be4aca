//! What a run costs, counted rather than timed: the work each step does (force evaluations,
//! linear-solver iterations, constraint or descent sweeps) weighed by fixed unit costs, so
//! the choice made from it is the same on every run and every machine. Wall time is
//! measured beside it and reported, never chosen by.

use std::time::Instant;

use crate::scene::{Scene, Simulation};
use crate::sim::{IntegratorKind, StepStats};

/// What one unit of each kind of work costs, in force evaluations of the same cloth (one
/// semi-implicit Euler substep: every force term once, and the update).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct UnitCosts {
    /// Implicit Euler's derivative assembly, per force evaluation.
    pub assembly: f64,
    /// One conjugate-gradient iteration.
    pub linear_iteration: f64,
    /// One XPBD sweep over the springs.
    pub xpbd_sweep: f64,
    /// One VBD sweep over the particles.
    pub vbd_sweep: f64,
    /// Where the numbers come from.
    pub source: String,
}

impl Default for UnitCosts {
    /// The calibration the report chooses by: `clothsim accuracy --calibrate` on the
    /// `hanging` scene (625 particles, below the size whose steps are shared between
    /// threads), 2026-11-26, the development machine (2 vCPUs of an AMD EPYC): three runs
    /// gave an assembly of 10.5–10.9, a CG iteration 0.75–0.77, an XPBD sweep 1.25–1.41, a
    /// VBD sweep 2.56–2.59 (one semi-implicit Euler substep 7.3–7.4 µs). The assembly is
    /// that 10.6 less what assembling in the springs' runs saved, 2026-12-06 on a 2-vCPU
    /// Intel Xeon host: the assembly alone on `hanging` took 64–72 µs before and 18–24
    /// after, 5.3 of that host's semi-implicit Euler substeps (8.5–9.5 µs). (`--calibrate`
    /// there, alternating with the build before: medians of 4.9 and 10.6 in a quiet hour,
    /// of 6.8 and 10.9 in a busy one.)
    fn default() -> Self {
        Self {
            assembly: 5.3,
            linear_iteration: 0.76,
            xpbd_sweep: 1.3,
            vbd_sweep: 2.6,
            source: "`clothsim accuracy --calibrate` on `hanging`, 625 particles, 2026-11-26, \
                     2 vCPUs of an AMD EPYC (the assembly 2026-12-06, after it went into the \
                     springs' runs)"
                .into(),
        }
    }
}

/// The work of a run, per step.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Work {
    pub force_evals: f64,
    /// Conjugate-gradient iterations (implicit Euler).
    pub linear_iterations: f64,
    /// Constraint sweeps (XPBD) or descent sweeps (VBD).
    pub sweeps: f64,
}

impl Work {
    /// The work `stats` counted under `integrator`, per step.
    pub fn per_step(integrator: IntegratorKind, stats: &StepStats) -> Self {
        let iterations = stats.solver_iterations_per_step();
        let (linear_iterations, sweeps) = match integrator {
            IntegratorKind::ImplicitEuler => (iterations, 0.0),
            IntegratorKind::Xpbd | IntegratorKind::Vbd => (0.0, iterations),
            _ => (0.0, 0.0),
        };
        Self {
            force_evals: stats.force_evals_per_step(),
            linear_iterations,
            sweeps,
        }
    }
}

impl UnitCosts {
    /// A step's cost under `integrator`, in force evaluations.
    pub fn step(&self, integrator: IntegratorKind, work: &Work) -> f64 {
        let evaluation = match integrator {
            IntegratorKind::ImplicitEuler => 1.0 + self.assembly,
            _ => 1.0,
        };
        let sweep = match integrator {
            IntegratorKind::Xpbd => self.xpbd_sweep,
            IntegratorKind::Vbd => self.vbd_sweep,
            _ => 0.0,
        };
        work.force_evals * evaluation
            + work.linear_iterations * self.linear_iteration
            + work.sweeps * sweep
    }
}

/// Wall time per step of `scene` under `integrator` at `substeps` a frame, with `edit`
/// applied, over at least 0.2 s of stepping; and what the steps counted.
fn time_steps(
    scene: &Scene,
    integrator: IntegratorKind,
    substeps: u32,
    edit: impl Fn(&mut Scene),
) -> (f64, StepStats) {
    let mut scene = scene.clone();
    scene.params.step.integrator = integrator;
    scene.params.step.substeps = substeps;
    scene.params.guard.enabled = false;
    edit(&mut scene);
    let mut sim = Simulation::new(scene);
    // Warm: the first steps build what the integrator keeps.
    for _ in 0..substeps {
        let _ = sim.substep();
    }
    let _ = sim.take_stats();
    let (start, mut steps) = (Instant::now(), 0u64);
    while steps < 50 || start.elapsed().as_secs_f64() < 0.2 {
        if sim.substep().is_err() {
            break;
        }
        steps += 1;
    }
    (
        start.elapsed().as_secs_f64() / steps as f64,
        sim.take_stats(),
    )
}

/// Measures the unit costs on `scene` on this machine: a semi-implicit Euler substep is the
/// unit; implicit Euler at two tolerances gives a CG iteration's cost (the difference over
/// the iterations it added) and the assembly (what is left); XPBD and VBD at one and five
/// sweeps give a sweep's. Timed, so it varies from run to run: for seeing how far this
/// machine and scene are from the built-in numbers, not for choosing.
pub fn calibrate(scene: &Scene) -> UnitCosts {
    let (unit, _) = time_steps(scene, IntegratorKind::SemiImplicitEuler, 48, |_| {});
    let implicit = |tolerance: f32| {
        let (t, stats) = time_steps(scene, IntegratorKind::ImplicitEuler, 4, |s| {
            s.params.solver.tolerance = tolerance;
        });
        (t / unit, stats.solver_iterations_per_step())
    };
    let ((t1, i1), (t2, i2)) = (implicit(1e-3), implicit(1e-6));
    let linear_iteration = ((t2 - t1) / (i2 - i1).max(1e-9)).max(0.0);
    let assembly = (t1 - i1 * linear_iteration - 1.0).max(0.0);
    let sweep = |integrator: IntegratorKind| {
        let at = |sweeps: u32| {
            let (t, _) = time_steps(scene, integrator, 48, |s| {
                s.params.solver.xpbd_iterations = sweeps;
                s.params.solver.vbd_iterations = sweeps;
            });
            t / unit
        };
        ((at(5) - at(1)) / 4.0).max(0.0)
    };
    UnitCosts {
        assembly,
        linear_iteration,
        xpbd_sweep: sweep(IntegratorKind::Xpbd),
        vbd_sweep: sweep(IntegratorKind::Vbd),
        source: format!(
            "measured on `{}`, {} particles, one substep of semi-implicit Euler {:.1} µs",
            scene.scenario,
            scene.model.particle_count(),
            unit * 1e6
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_steps_cost_weighs_each_kind_of_work_by_its_unit() {
        let units = UnitCosts {
            assembly: 2.0,
            linear_iteration: 0.5,
            xpbd_sweep: 1.5,
            vbd_sweep: 3.0,
            source: String::new(),
        };
        let work = |force_evals, linear_iterations, sweeps| Work {
            force_evals,
            linear_iterations,
            sweeps,
        };
        assert_eq!(units.step(IntegratorKind::Rk4, &work(4.0, 0.0, 0.0)), 4.0);
        let implicit = units.step(IntegratorKind::ImplicitEuler, &work(2.0, 10.0, 0.0));
        assert_eq!(implicit, 2.0 * 3.0 + 5.0);
        assert_eq!(
            units.step(IntegratorKind::Xpbd, &work(1.0, 0.0, 4.0)),
            1.0 + 6.0
        );
        assert_eq!(
            units.step(IntegratorKind::Vbd, &work(1.0, 0.0, 4.0)),
            1.0 + 12.0
        );
    }
}
