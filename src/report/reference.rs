//! The reference trajectory every run is judged against: RK4 at the step where it is surest
//! of itself.

use crate::mesh::bbox_diagonal;
use crate::scene::Scene;
use crate::sim::IntegratorKind;

use super::config::SweepConfig;
use super::measure::{Record, Trajectory, position_error, run, undamped};
use super::order::RESOLVED;
use super::shape::{Judged, shape_error};

/// The reference's finest candidate step is this many times below the smallest swept step.
pub const REFERENCE_REFINEMENT: f64 = 4.0;

/// The reference trajectory and how well it is converged.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Reference {
    pub integrator: IntegratorKind,
    /// Its step, seconds.
    pub dt: f64,
    /// RMS and maximum difference (fractions of the cloth's size) between the reference and
    /// the same method at twice its step: its uncertainty.
    pub check_rms: f64,
    pub check_max: f64,
    /// The same pair's difference in shape ([`super::shape_error`]: fraction of the cloth's
    /// size), the uncertainty of shape errors.
    pub check_shape: f64,
    /// What runs are judged by (see [`Reference::judge`]).
    pub judged: Judged,
    /// Peak kinetic energy of the undamped scene, joules: the scale of energy drift.
    pub peak_kinetic: f64,
    /// Every candidate step but the finest (seconds), and how far its run is from the run at
    /// half its step (maximum, fraction of the cloth's size; infinite where either blew up).
    pub ladder: Vec<(f64, f64)>,
    /// Each candidate step finer than the reference's, and how far its run is from the
    /// reference: RK4's own error is negligible there, so this is what f32 rounding adds
    /// over that many steps, the floor under any run at such a step.
    pub rounding: Vec<(f64, f64)>,
}

impl Reference {
    /// Decides what runs are judged by for `tolerance`: their trajectories, unless the
    /// reference is too unsure of its own to resolve an error at the tolerance (ten times
    /// its uncertainty above it): then the trajectory is chaotic over the horizon, and runs
    /// are judged by the shape in aggregate.
    pub fn judge(&mut self, tolerance: f64) {
        self.judged = if RESOLVED * self.check_max > tolerance {
            Judged::Shape
        } else {
            Judged::Trajectory
        };
    }

    /// Below this error (a fraction of the cloth's size) a run at step `dt` measures the
    /// reference's uncertainty or its own rounding as much as its method: the larger of the
    /// reference's uncertainty and the rounding at the candidate step nearest `dt` (for
    /// steps finer than the reference's).
    pub fn floor(&self, dt: f64) -> f64 {
        let nearest = (self.rounding.iter())
            .filter(|_| dt < self.dt * 0.999)
            .min_by(|a, b| (a.0 / dt).ln().abs().total_cmp(&(b.0 / dt).ln().abs()));
        nearest.map_or(self.check_max, |r| r.1.max(self.check_max))
    }
}

/// The cloth's size (bounding-box diagonal of its start), metres.
pub fn scene_size(scene: &Scene) -> f64 {
    (bbox_diagonal(&scene.initial.pos) as f64).max(1e-9)
}

/// The candidate steps: from [`REFERENCE_REFINEMENT`] times below the smallest swept step,
/// doubling, up to the largest swept step.
fn ladder_steps(config: &SweepConfig) -> Vec<f64> {
    let smallest = config.dts.iter().copied().fold(f64::INFINITY, f64::min);
    let largest = config.dts.iter().copied().fold(0.0, f64::max);
    let mut steps = vec![smallest / REFERENCE_REFINEMENT];
    while let Some(&h) = steps.last() {
        if 2.0 * h > largest * 1.0001 || steps.len() >= 40 {
            break;
        }
        steps.push(2.0 * h);
    }
    steps
}

/// Runs RK4 at every candidate step and keeps the one that differs least from the next
/// coarser: in f32 a smaller step is not always surer (rounding grows with the steps taken
/// while the method's own error shrinks), so the reference is the finer of the two
/// neighbouring steps that agree best, and their difference is its uncertainty. Also runs
/// the undamped scene (RK4 at the smallest swept step), whose peak kinetic energy sets the
/// scale of energy drift.
pub fn reference(scene: &Scene, config: &SweepConfig) -> (Trajectory, Reference) {
    let steps = ladder_steps(config);
    let (seconds, samples) = (config.seconds, config.samples);
    let rk4 = IntegratorKind::Rk4;
    let one = |h: f64| run(scene, rk4, h, seconds, samples, Record::Positions);
    let runs: Vec<Trajectory> = if config.parallel_reference && steps.len() > 1 {
        // The odd steps on a second thread, the even ones (the finest, the dearest, among
        // them) on this one; then put back in order.
        let (evens, odds) = std::thread::scope(|s| {
            let other = s.spawn(|| {
                let odds = steps.iter().skip(1).step_by(2);
                odds.map(|&h| one(h)).collect::<Vec<Trajectory>>()
            });
            let other = || {
                other
                    .join()
                    .unwrap_or_else(|e| std::panic::resume_unwind(e))
            };
            let evens: Vec<Trajectory> = steps.iter().step_by(2).map(|&h| one(h)).collect();
            (evens, other())
        });
        let mut odds = odds.into_iter();
        (evens.into_iter())
            .flat_map(|even| std::iter::once(even).chain(odds.next()))
            .collect()
    } else {
        steps.iter().map(|&h| one(h)).collect()
    };
    let size = scene_size(scene);
    let differences: Vec<(f64, f64)> = (1..runs.len())
        .map(|j| {
            let (rms, max) = position_error(&runs[j], &runs[j - 1]);
            (rms / size, max / size)
        })
        .collect();
    let best = (0..differences.len())
        .filter(|&j| differences[j].1.is_finite())
        .min_by(|&a, &b| differences[a].1.total_cmp(&differences[b].1));
    let (chosen, (check_rms, check_max)) = match best {
        Some(j) => (j, differences[j]),
        // One candidate, or none agreeing: the finest, unchecked.
        None => (0, (f64::INFINITY, f64::INFINITY)),
    };
    let smallest = config.dts.iter().copied().fold(f64::INFINITY, f64::min);
    let energy = run(
        &undamped(scene),
        rk4,
        smallest,
        seconds,
        samples * 2,
        Record::Energy,
    );
    let ladder = (1..runs.len())
        .map(|j| (runs[j].h, differences[j - 1].1))
        .collect();
    let check_shape = match best {
        Some(j) => shape_error(&scene.model, &runs[j + 1], &runs[j], size).0,
        None => f64::INFINITY,
    };
    let rounding = (0..chosen)
        .map(|j| (runs[j].h, position_error(&runs[j], &runs[chosen]).1 / size))
        .collect();
    let mut runs = runs;
    let main = runs.swap_remove(chosen);
    let info = Reference {
        integrator: rk4,
        dt: main.h,
        check_rms,
        check_max,
        check_shape,
        judged: Judged::Trajectory,
        peak_kinetic: energy.peak_kinetic(),
        ladder,
        rounding,
    };
    (main, info)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Finer than the reference, a run's floor is the rounding RK4 showed at the candidate
    /// step nearest its own (when above the uncertainty); at or above the reference's step,
    /// the uncertainty alone.
    #[test]
    fn a_runs_floor_is_the_rounding_at_its_step_or_the_references_uncertainty() {
        let reference = Reference {
            integrator: IntegratorKind::Rk4,
            dt: 1e-3,
            check_rms: 1e-7,
            check_max: 2e-7,
            check_shape: 1e-7,
            judged: Judged::Trajectory,
            peak_kinetic: 1.0,
            ladder: Vec::new(),
            rounding: vec![(1.25e-4, 3e-6), (2.5e-4, 1e-6), (5e-4, 1e-7)],
        };
        assert_eq!(reference.floor(1.3e-4), 3e-6);
        assert_eq!(reference.floor(2.2e-4), 1e-6);
        assert_eq!(
            reference.floor(5e-4),
            2e-7,
            "rounding below the uncertainty"
        );
        assert_eq!(reference.floor(1e-3), 2e-7);
        assert_eq!(reference.floor(4e-3), 2e-7);
    }
}
