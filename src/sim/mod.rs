//! The CPU solver: forces, colliders, integrators and the stepper that composes them.
//! Pure CPU code with no graphics dependency; deterministic.

mod backend;
mod cg;
mod collider;
mod constraints;
mod cpu_stepper;
mod effect;
pub mod forces;
mod guard;
mod guard_state;
pub mod integrator;
mod params;
mod self_collision;
mod stats;
pub mod team;
mod timings;
mod wide;

pub use backend::StepBackend;
pub use cg::{CgOutcome, ConjugateGradient};
pub use collider::{Collider, colliders_of, min_collider_distance, small_sphere_warnings};
pub use constraints::DistanceConstraints;
pub use cpu_stepper::CpuStepper;
pub use effect::{BendingModel, Effect, wind_of};
pub use forces::{Force, ForceSet, JacobianMode, SystemMatrix, Wind};
pub use guard::{
    Diverged, FrameOutcome, GuardAction, GuardEvent, GuardLimits, GuardPolicy, Trouble, check,
};
pub use integrator::{Integrator, IntegratorKind, StepContext, StepError, StepMeter, StepReport};
pub use params::{SimParams, SolverConfig};
pub use self_collision::{SelfCollision, SelfContacts, SelfWork};
pub use stats::StepStats;
pub use timings::{Phase, PhaseTimings};
