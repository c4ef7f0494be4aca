//! What a sweep runs: which integrators, at which steps, for how long, judged how.

use crate::scene::Scene;
use crate::sim::{IntegratorKind, Precision};

use super::cost::UnitCosts;
use super::error::ReportError;

/// What to sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepConfig {
    pub integrators: Vec<IntegratorKind>,
    /// Step sizes, seconds (each is adjusted so whole steps fill a sample interval).
    pub dts: Vec<f64>,
    /// Simulated seconds of each run.
    pub seconds: f64,
    /// Times along the trajectory at which positions are compared.
    pub samples: u32,
    /// Largest acceptable error (position, or shape on a chaotic scene), as a fraction of
    /// the cloth's size.
    pub tolerance: f64,
    /// Bisection steps when searching each integrator's largest stable step (0: none).
    pub bisection_steps: u32,
    /// Run the reference's candidate steps on two threads.
    pub parallel_reference: bool,
    /// What each kind of work costs: the choice is made by counted work weighed by these.
    pub unit_costs: UnitCosts,
    /// What every run of the sweep (its reference too) computes in: `f64` unless told
    /// otherwise, so that rounding stays far below the errors measured.
    pub precision: Precision,
}

/// The default sweep: a 1/60 s frame divided into 3 … 384 substeps (2.1 decades of step).
pub const DEFAULT_SUBSTEPS: [u32; 8] = [3, 6, 12, 24, 48, 96, 192, 384];
/// The default tolerance: every particle within 1 % of the cloth's size of the reference.
pub const DEFAULT_TOLERANCE: f64 = 0.01;

impl Default for SweepConfig {
    fn default() -> Self {
        Self {
            integrators: IntegratorKind::ALL.to_vec(),
            dts: DEFAULT_SUBSTEPS
                .iter()
                .map(|&n| 1.0 / (60.0 * n as f64))
                .collect(),
            // Long enough for a cloth to swing well down; short enough that a folding one
            // (`hanging`) has not yet turned chaotic (over 1.5 s its reference is unsure of
            // its positions by 2 % of its size).
            seconds: 0.25,
            // One comparison per 1/60 s frame.
            samples: 15,
            tolerance: DEFAULT_TOLERANCE,
            bisection_steps: 6,
            parallel_reference: true,
            unit_costs: UnitCosts::default(),
            precision: Precision::F64,
        }
    }
}

/// The scene the report runs unless told another: every integrator's order shows on it.
pub const ORDERS_SCENE: &str = "orders";

/// The `orders` sweep's substeps per 1/60 s frame: 1 to 4 in steps of √2 (where RK4's error
/// falls through its resolved range), then doubling to 1 024 (where the first-order methods'
/// does).
pub const ORDERS_SUBSTEPS: [f64; 13] = [
    1.0,
    std::f64::consts::SQRT_2,
    2.0,
    2.0 * std::f64::consts::SQRT_2,
    4.0,
    8.0,
    16.0,
    32.0,
    64.0,
    128.0,
    256.0,
    512.0,
    1024.0,
];

impl SweepConfig {
    /// `scene` set up to run in the sweep's precision.
    pub fn in_precision(&self, scene: &Scene) -> Scene {
        let mut scene = scene.clone();
        scene.params.solver.precision = self.precision;
        scene
    }

    /// The sweep for the scene called `name`: on [`ORDERS_SCENE`] one second at
    /// [`ORDERS_SUBSTEPS`] (smooth for a second, and the orders need the span), one sample
    /// every 1/30 s; on any other the default, a quarter second at [`DEFAULT_SUBSTEPS`]
    /// (before a folding cloth turns chaotic).
    pub fn for_scene(name: &str) -> Self {
        if name != ORDERS_SCENE {
            return Self::default();
        }
        Self {
            dts: ORDERS_SUBSTEPS.iter().map(|n| 1.0 / (60.0 * n)).collect(),
            seconds: 1.0,
            samples: 30,
            ..Self::default()
        }
    }

    /// Checks that the sweep can run.
    ///
    /// # Errors
    /// [`ReportError::Config`] naming the bad value.
    pub fn validate(&self) -> Result<(), ReportError> {
        let bad = |what: String| Err(ReportError::Config(what));
        if self.integrators.is_empty() {
            return bad("no integrators to sweep".into());
        }
        if self.dts.is_empty() {
            return bad("no step sizes to sweep".into());
        }
        if let Some(dt) = self
            .dts
            .iter()
            .find(|d| !(d.is_finite() && **d > 0.0 && **d <= 0.1))
        {
            return bad(format!("step size {dt} s is out of range (0 < dt ≤ 0.1 s)"));
        }
        if !(self.seconds.is_finite() && self.seconds > 0.0 && self.seconds <= 60.0) {
            return bad(format!(
                "--seconds {} is out of range (0 < T ≤ 60 s)",
                self.seconds
            ));
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return bad(format!(
                "--tolerance {} must be a positive number",
                self.tolerance
            ));
        }
        if self.samples == 0 {
            return bad("at least one sample time is needed".into());
        }
        Ok(())
    }
}
