//! A force term with the phase its time is charged to ([`Force`]), as an effect builds it.

use std::any::Any;

use crate::cloth::ClothModel;
use crate::sim::params::Material;

use super::force_term::ForceTerm;
use super::springs::SpringForce;

/// A force term of a scene, with the phase its time is charged to (its effect's name).
#[derive(Debug)]
pub struct Force {
    phase: &'static str,
    term: Box<dyn ForceTerm>,
}

impl Force {
    /// `term`, its time charged to `phase`.
    pub fn new(phase: &'static str, term: impl ForceTerm) -> Self {
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
    pub fn get<T: ForceTerm>(&self) -> Option<&T> {
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
impl std::ops::Deref for Force {
    type Target = dyn ForceTerm;

    fn deref(&self) -> &Self::Target {
        &*self.term
    }
}
