//! The integrator interface: one substep in, a report or a typed failure out.

use crate::cloth::{ClothState, Real};

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};

/// Advances a cloth state by one substep of `h` seconds, in precision `R`.
///
/// Contract: afterwards `state.vel` holds the velocities at the new time, `state.time` is
/// advanced by `h`, and particles with inverse mass 0 have not moved. Whatever an
/// integrator keeps between steps (a last acceleration) is dropped by
/// [`Integrator::invalidate`], which the stepper calls whenever the state or the model
/// change outside the integrator, and by [`Integrator::forces_changed`] when the parameters
/// do.
pub trait Integrator<R: Real = f32>: Send {
    fn kind(&self) -> IntegratorKind;

    /// One step.
    ///
    /// # Errors
    /// [`StepError`] when the step's solve failed; the state is then spoiled and the
    /// caller rolls back.
    fn step(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
    ) -> Result<StepReport, StepError>;

    /// `count` steps in a row, where this integrator has a faster way to take them than one
    /// at a time; the stepper asks when nothing outside the integrator reads or changes the
    /// state between them (a frame's substeps without contacts). The states are exactly
    /// those of `count` calls to [`Integrator::step`]; the report counts all the steps'
    /// work. `None`, with nothing changed, where there is no faster way (the default), or
    /// where the forces depend on time (the stepper sets it before each step only).
    fn steps(
        &mut self,
        _ctx: &mut StepContext<'_, R>,
        _state: &mut ClothState<R>,
        _h: R,
        _count: u32,
    ) -> Option<Result<StepReport, StepError>> {
        None
    }

    /// Forgets what was kept from earlier steps: the state changed outside the integrator
    /// (a rollback, a pin or density change, a drag).
    fn invalidate(&mut self) {}

    /// Contacts moved particles and changed their velocities after the last step: by
    /// default as [`Integrator::invalidate`].
    fn contacts_moved(&mut self) {
        self.invalidate();
    }

    /// The forces or their strengths changed: drops whatever was derived from them, and
    /// whatever was kept from earlier steps.
    fn forces_changed(&mut self) {
        self.invalidate();
    }
}
