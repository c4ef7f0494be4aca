//! Counters of the work steps did, for cost reports.

use super::integrator::StepReport;

/// Work summed over steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    pub steps: u64,
    pub force_evals: u64,
    pub solver_iterations: u64,
    /// Largest final relative residual of any linear solve.
    pub max_residual: Option<f32>,
    /// Steps whose linear solve stopped at its cap above the tolerance.
    pub unconverged: u64,
}

impl StepStats {
    /// Adds one step's report.
    pub fn record(&mut self, report: &StepReport) {
        self.steps += 1;
        self.force_evals += report.force_evals as u64;
        self.solver_iterations += report.solver_iterations as u64;
        if let Some(r) = report.residual {
            self.max_residual = Some(self.max_residual.map_or(r, |m| m.max(r)));
        }
        if !report.converged {
            self.unconverged += 1;
        }
    }

    /// Adds `count` steps taken together, `report` counting the work of all of them (an
    /// unconverged solve among them counts once).
    pub fn record_steps(&mut self, report: &StepReport, count: u32) {
        self.record(report);
        self.steps += count.saturating_sub(1) as u64;
    }

    /// Force evaluations per step (0 without steps).
    pub fn force_evals_per_step(&self) -> f64 {
        self.force_evals as f64 / self.steps.max(1) as f64
    }

    /// Linear-solver iterations per step (0 without steps).
    pub fn solver_iterations_per_step(&self) -> f64 {
        self.solver_iterations as f64 / self.steps.max(1) as f64
    }
}
