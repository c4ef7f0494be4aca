//! One point of the accuracy sweep: an integrator at a step, its error and cost.

use crate::sim::IntegratorKind;

/// One integrator at one step size.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Point {
    pub integrator: IntegratorKind,
    /// The step taken, seconds.
    pub dt: f64,
    /// Steps taken over the run.
    pub steps: u64,
    /// The scene's frame time ÷ dt: the substeps per frame that give this step.
    pub substeps_per_frame: f64,
    /// Position error against the reference: the largest over sample times of the RMS over
    /// particles, as a fraction of the cloth's size.
    pub rms_error: f64,
    /// The same for the maximum over particles.
    pub max_error: f64,
    /// Energy drift on the undamped scene: largest deviation of the total energy from its
    /// start (gain or loss), as a fraction of the reference's peak kinetic energy.
    pub energy_drift: f64,
    /// Finite throughout, with energy bounded (it never gained more than the reference's
    /// peak kinetic energy) and error below the cloth's size.
    pub stable: bool,
    /// The larger of the reference's uncertainty and the rounding RK4 shows at this step
    /// (fraction of the cloth's size; see [`super::Reference::floor`]).
    pub floor: f64,
    /// How far the shape in aggregate strays from the reference's (centre of mass and
    /// spread, fraction of the cloth's size; see [`super::shape_error`]), and the mean
    /// structural strain's largest difference.
    pub shape_error: f64,
    pub strain_error: f64,
    /// The reference's own uncertainty in shape.
    pub shape_floor: f64,
    /// What the report judges this run by: its position error, or (on a scene chaotic over
    /// the horizon) its shape error.
    pub judged: super::Judged,
    /// Wall-clock seconds per simulated second (measured; varies from run to run).
    pub wall_s_per_sim_s: f64,
    /// The counted work per simulated second, in force evaluations of this cloth (see
    /// [`super::UnitCosts`]): the cost the choice is made by, the same on every run.
    pub work_per_sim_s: f64,
    pub force_evals_per_step: f64,
    /// Conjugate-gradient iterations per step (implicit Euler).
    pub linear_iterations_per_step: f64,
    /// Constraint (XPBD) or descent (VBD) sweeps per step.
    pub sweeps_per_step: f64,
    /// On a scene with solids or self-collision: the deepest penetration and the most
    /// intersections at a sample time.
    pub contact: Option<super::ContactMeasures>,
}

impl Point {
    /// The substeps per frame as a whole number, where the frame holds this step a whole
    /// number of times (to the f32 rounding of the frame's length); `None` for steps such
    /// as √2 substeps a frame.
    pub fn whole_substeps(&self) -> Option<u32> {
        let n = self.substeps_per_frame;
        let whole = n >= 0.5 && (n - n.round()).abs() <= 1e-4 * n;
        whole.then(|| n.round() as u32)
    }

    /// The error the run is judged by ([`Point::judged`]) and the floor it may be lost in.
    pub fn judged_error(&self) -> (f64, f64) {
        match self.judged {
            super::Judged::Trajectory => (self.max_error, self.floor),
            super::Judged::Shape => (self.shape_error, self.shape_floor),
        }
    }

    /// Whether the judged error is at least ten times its floor; below, it measures the
    /// reference or the run's rounding as much as the method.
    pub fn resolved(&self) -> bool {
        let (error, floor) = self.judged_error();
        error >= super::RESOLVED * floor
    }

    /// What the judged error is known to be below: the error where resolved, else ten
    /// times the floor it is lost in. The frontier and the choice rank points by it.
    pub fn error_bound(&self) -> f64 {
        let (error, floor) = self.judged_error();
        error.max(super::RESOLVED * floor)
    }
}

#[cfg(test)]
impl Point {
    /// An RK4 point of this counted cost and error (tests: the rest are placeholders; its
    /// wall time runs against its cost, so a choice by wall time would differ).
    pub(crate) fn at(cost: f64, error: f64, stable: bool) -> Self {
        Self {
            integrator: IntegratorKind::Rk4,
            dt: 1e-3,
            steps: 1,
            substeps_per_frame: 1.0,
            rms_error: error,
            max_error: error,
            energy_drift: 0.0,
            stable,
            floor: 0.0,
            shape_error: error,
            strain_error: 0.0,
            shape_floor: 0.0,
            judged: super::Judged::Trajectory,
            wall_s_per_sim_s: 1.0 / cost,
            work_per_sim_s: cost,
            force_evals_per_step: 1.0,
            linear_iterations_per_step: 0.0,
            sweeps_per_step: 0.0,
            contact: None,
        }
    }
}
