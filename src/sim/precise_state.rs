//! The state a stepper in a precision other than `f32` keeps ([`PreciseState`]), and the
//! `f32` views of it that the guard and the contacts read and write ([`as_f32`],
//! [`f32_view`]). In `f32` both views are the state itself: nothing is copied.

use std::any::Any;

use crate::cloth::{ClothState, Real};

/// `state` as an `f32` state for reading: the state itself in `f32`; else its rounding,
/// written into `view`.
pub fn f32_view<'a, R: Real>(state: &'a ClothState<R>, view: &'a mut ClothState) -> &'a ClothState {
    if let Some(same) = (state as &dyn Any).downcast_ref::<ClothState>() {
        return same;
    }
    view.take(state);
    view
}

/// Runs `f` on `state` as an `f32` state: on the state itself in `f32`; else on its
/// rounding in `view`, after which every particle `f` changed takes the new `f32` values
/// (the others keep all their digits). What `f` does is computed in `f32` either way (the
/// contacts: a push out of a solid is a decision, not a quantity the precision refines).
pub fn as_f32<R: Real, T>(
    state: &mut ClothState<R>,
    view: &mut ClothState,
    f: impl FnOnce(&mut ClothState) -> T,
) -> T {
    if let Some(same) = (state as &mut dyn Any).downcast_mut::<ClothState>() {
        return f(same);
    }
    view.take(state);
    let out = f(view);
    let particles =
        (state.pos.iter_mut().zip(state.vel.iter_mut())).zip(view.pos.iter().zip(&view.vel));
    for ((x, v), (x32, v32)) in particles {
        if R::v3_f32(*x) != *x32 || R::v3_f32(*v) != *v32 {
            *x = R::v3(*x32);
            *v = R::v3(*v32);
        }
    }
    state.time = view.time;
    out
}

/// The state a stepper in a precision other than `f32` steps, beside the caller's `f32`
/// state, which after each frame holds its rounding. The caller's state is taken again
/// after the stepper is told it changed ([`PreciseState::forget`], from
/// [`StepBackend::invalidate`](super::backend::StepBackend::invalidate): a drag, a reset, an
/// edit), as the GPU backend takes it again into its buffers.
#[derive(Debug)]
pub struct PreciseState<R: Real> {
    pub state: ClothState<R>,
    stale: bool,
}

impl<R: Real> Default for PreciseState<R> {
    fn default() -> Self {
        Self {
            state: ClothState::default(),
            stale: true,
        }
    }
}

impl<R: Real> PreciseState<R> {
    /// The caller's state changed: take it before the next step.
    pub fn forget(&mut self) {
        self.stale = true;
    }

    /// Whether the state stepped is the caller's to more digits (nothing changed the
    /// caller's since it was written).
    pub fn holds(&self) -> bool {
        !self.stale
    }

    /// Takes `given` if the caller's state changed since it was last written.
    pub fn load(&mut self, given: &ClothState) {
        if self.stale {
            self.state.take(given);
            self.stale = false;
        }
    }

    /// Writes the rounding of the state stepped into `given`.
    pub fn store(&self, given: &mut ClothState) {
        given.take(&self.state);
    }
}
