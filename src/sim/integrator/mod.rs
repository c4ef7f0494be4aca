//! Time integrators. All share one signature ([`Integrator`]); the UI and CLI pick one by
//! [`IntegratorKind`]. Each integrator owns its scratch buffers and gets forces, its
//! configuration and a meter through [`StepContext`].

mod context;
mod kind;
mod semi_implicit_euler;
mod step;
mod velocity_verlet;

pub use context::{StepContext, StepMeter};
pub use kind::IntegratorKind;
pub use semi_implicit_euler::SemiImplicitEuler;
pub use step::{Integrator, StepError, StepReport};
pub use velocity_verlet::VelocityVerlet;
