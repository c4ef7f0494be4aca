//! Building an integrator from its kind: the one place that names every integrator type.

use crate::cloth::Real;

use super::explicit_euler::ExplicitEuler;
use super::implicit_euler::ImplicitEuler;
use super::kind::IntegratorKind;
use super::rk2::Rk2;
use super::rk4::Rk4;
use super::semi_implicit_euler::SemiImplicitEuler;
use super::step::Integrator;
use super::vbd::Vbd;
use super::velocity_verlet::VelocityVerlet;
use super::xpbd::Xpbd;

impl IntegratorKind {
    /// A fresh integrator of this kind, in precision `R`.
    pub fn build<R: Real>(self) -> Box<dyn Integrator<R>> {
        match self {
            IntegratorKind::ExplicitEuler => Box::new(ExplicitEuler::default()),
            IntegratorKind::SemiImplicitEuler => Box::new(SemiImplicitEuler::default()),
            IntegratorKind::Verlet => Box::new(VelocityVerlet::default()),
            IntegratorKind::Rk2 => Box::new(Rk2::default()),
            IntegratorKind::Rk4 => Box::new(Rk4::default()),
            IntegratorKind::ImplicitEuler => Box::new(ImplicitEuler::default()),
            IntegratorKind::Xpbd => Box::new(Xpbd::default()),
            IntegratorKind::Vbd => Box::new(Vbd::default()),
        }
    }
}
