//! The integrator interface: one substep in, a report or a typed failure out.

use crate::cloth::ClothState;
use crate::sim::self_collision::ContactError;

use super::context::StepContext;
use super::kind::IntegratorKind;

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

/// Advances a cloth state by one substep of `h` seconds.
///
/// Contract: afterwards `state.vel` holds the velocities at the new time, `state.time` is
/// advanced by `h`, and particles with inverse mass 0 have not moved. Whatever an
/// integrator keeps between steps (a last acceleration) is dropped by
/// [`Integrator::invalidate`], which the stepper calls whenever the state or the model
/// change outside the integrator, and by [`Integrator::forces_changed`] when the parameters
/// do.
pub trait Integrator: Send {
    fn kind(&self) -> IntegratorKind;

    /// One step.
    ///
    /// # Errors
    /// [`StepError`] when the step's solve failed; the state is then spoiled and the
    /// caller rolls back.
    fn step(
        &mut self,
        ctx: &mut StepContext<'_>,
        state: &mut ClothState,
        h: f32,
    ) -> Result<StepReport, StepError>;

    /// `count` steps in a row, where this integrator has a faster way to take them than one
    /// at a time; the stepper asks when nothing outside the integrator reads or changes the
    /// state between them (a frame's substeps without contacts). The states are exactly
    /// those of `count` calls to [`Integrator::step`]; the report counts all the steps'
    /// work. `None`, with nothing changed, where there is no faster way (the default), or
    /// where the forces depend on time (the stepper sets it before each step only).
    fn steps(
        &mut self,
        _ctx: &mut StepContext<'_>,
        _state: &mut ClothState,
        _h: f32,
        _count: u32,
    ) -> Option<Result<StepReport, StepError>> {
        None
    }

    /// Forgets what was kept from earlier steps: the state changed outside the integrator
    /// (a contact, a rollback, a pin or density change, a drag).
    fn invalidate(&mut self) {}

    /// The forces or their strengths changed: drops whatever was derived from them, and
    /// whatever was kept from earlier steps.
    fn forces_changed(&mut self) {
        self.invalidate();
    }
}
