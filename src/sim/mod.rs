//! The CPU solver: forces, colliders, integrators and the stepper that composes them.
//! Pure CPU code with no graphics dependency; deterministic.

mod collider;
mod effect;
mod forces;
pub mod integrator;
mod params;
mod stepper;
mod timings;

pub use collider::{Collider, min_collider_distance};
pub use effect::Effect;
pub use forces::{Force, ForceSet};
pub use integrator::{Integrator, IntegratorKind, StepContext};
pub use params::SimParams;
pub use stepper::{Diverged, FrameOutcome, Stepper};
pub use timings::PhaseTimings;
