//! Time integrators. All share one signature ([`Integrator`]); the UI and CLI pick one by
//! [`IntegratorKind`]. Each integrator owns its scratch buffers and gets forces, its
//! configuration and a meter through [`StepContext`].

mod build;
mod context;
mod explicit_euler;
mod implicit_euler;
mod kind;
mod report;
mod rk2;
mod rk4;
mod semi_implicit_euler;
mod stability;
mod step;
mod vbd;
mod velocity_verlet;
mod xpbd;

pub use context::{StepContext, StepMeter};
pub use explicit_euler::ExplicitEuler;
pub use implicit_euler::ImplicitEuler;
pub use kind::IntegratorKind;
pub use report::{StepError, StepReport};
pub use rk2::Rk2;
pub use rk4::Rk4;
pub use semi_implicit_euler::SemiImplicitEuler;
pub use step::Integrator;
pub use vbd::Vbd;
pub use velocity_verlet::VelocityVerlet;
pub use xpbd::Xpbd;
