//! A force term with the phase its time is charged to ([`Force`]), as an effect builds it.

use std::any::Any;

use crate::cloth::{ClothModel, Real};
use crate::sim::params::Material;

use super::force_term::ForceTerm;
use super::springs::SpringForce;

/// A force term of a scene, with the phase its time is charged to (its effect's name).
#[derive(Debug)]
pub struct Force<R: Real = f32> {
    phase: &'static str,
    term: Box<dyn ForceTerm<R>>,
}

impl Force {
    /// `term` in `f32`, its time charged to `phase`.
    pub fn new(phase: &'static str, term: impl ForceTerm) -> Self {
        Self::of(phase, term)
    }
}

impl<R: Real> Force<R> {
    /// `term`, its time charged to `phase`.
    pub fn of(phase: &'static str, term: impl ForceTerm<R>) -> Self {
        Self {
            phase,
            term: Box::new(term),
        }
    }

    /// The term's phase name in timings.
    pub fn phase(&self) -> &'static str {
        self.phase
    }

    /// Takes the material's new strengths ([`ForceTerm::retune`]).
    pub fn retune(&mut self, model: &ClothModel, material: &Material) {
        self.term.retune(model, material);
    }

    /// The term as its own type, if it is a `T`.
    pub fn get<T: ForceTerm<R>>(&self) -> Option<&T> {
        let any: &dyn Any = &*self.term;
        any.downcast_ref()
    }

    /// The spring term, if this is one (structural and shear, or bend springs).
    pub fn springs(&self) -> Option<&SpringForce> {
        self.get()
    }
}

/// A term is used through what it computes: `term.add_forces(…)` calls its
/// [`ForceTerm`] methods.
impl<R: Real> std::ops::Deref for Force<R> {
    type Target = dyn ForceTerm<R>;

    fn deref(&self) -> &Self::Target {
        &*self.term
    }
}
