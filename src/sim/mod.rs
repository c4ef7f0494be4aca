//! The CPU solver: forces, colliders, integrators and the stepper that composes them.
//! Pure CPU code with no graphics dependency; deterministic.

mod backend;
mod cg;
mod collider;
mod constraints;
mod cpu_stepper;
mod diagnosis;
mod effect;
pub mod forces;
mod guard;
mod guard_policy;
mod guard_state;
pub mod integrator;
pub mod kernels;
mod param_error;
mod params;
mod self_collision;
mod stats;
mod timings;

pub use backend::StepBackend;
pub use cg::{CgOutcome, ConjugateGradient};
pub use collider::{Collider, min_collider_distance, small_sphere_warnings};
pub use constraints::DistanceConstraints;
pub use cpu_stepper::CpuStepper;
pub use diagnosis::{Cause, Vibration, stiffest_vibration};
pub use effect::{BendingModel, Effect, colliders_of, thickness_fits, wind_of};
pub use forces::{Force, ForceSet, JacobianMode, SystemMatrix, Wind};
pub use guard::{Diverged, FrameOutcome, GuardAction, GuardEvent, GuardLimits, Trouble, check};
pub use guard_policy::GuardPolicy;
pub use integrator::{Integrator, IntegratorKind, StepContext, StepError, StepMeter, StepReport};
pub use param_error::ParamError;
pub use params::{SimParams, SolverConfig};
pub use self_collision::{
    CELLS_PER_TRIANGLE, ContactError, SelfCollision, SelfContacts, SelfWork, TooThick,
    shortest_edge,
};
pub use stats::StepStats;
pub use timings::{Phase, PhaseTimings};
