//! What a step reports: its cost, or why it could not be taken.

use crate::sim::self_contacts::ContactError;

/// What one step cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Force evaluations (each over every term and particle).
    pub force_evals: u32,
    /// Linear-solver iterations (implicit methods) or constraint sweeps (position-based).
    pub solver_iterations: u32,
    /// Final relative residual of the linear solve, when there was one.
    pub residual: Option<f32>,
    /// False when the linear solver stopped at its iteration cap above its tolerance.
    pub converged: bool,
}

/// A step that could not be taken; the state must be treated as spoiled.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StepError {
    /// Conjugate gradients met a direction of non-positive curvature: the system matrix is
    /// not positive definite.
    #[error(
        "the linear solve broke down after {iterations} iterations: the system is not positive definite"
    )]
    Breakdown { iterations: u32 },
    /// The solve produced NaN or infinity.
    #[error("the linear solve produced non-finite values after {iterations} iterations")]
    NonFinite { iterations: u32 },
    /// The backend cannot run what the scene asks for (the GPU backend and wind, say).
    #[error("{0}")]
    Unsupported(String),
    /// The device stepping the cloth failed (a GPU read-back, say).
    #[error("the device failed: {0}")]
    Device(String),
    /// Contact detection refused a state that has blown up (non-finite, or spread over
    /// absurd distances) instead of allocating for it.
    #[error("contact detection refused the state: {0}")]
    Contact(#[from] ContactError),
}
