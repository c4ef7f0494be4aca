//! The CPU solver: effects, forces, contacts, integrators and the stepper that composes
//! them. Pure CPU code with no graphics dependency; deterministic.

mod backend;
mod cg;
mod constraints;
mod cpu_stepper;
mod diagnosis;
pub mod effects;
pub mod forces;
mod guard;
mod guard_policy;
mod guard_state;
pub mod integrator;
pub mod intersections;
pub mod kernels;
mod motion;
pub mod obstacle;
mod param_error;
mod params;
mod precise_state;
mod precision;
mod self_contacts;
mod stats;
mod timings;

pub use backend::StepBackend;
pub use cg::{CgOutcome, ConjugateGradient};
pub use constraints::{DistanceConstraints, Halves};
pub use cpu_stepper::{BETWEEN_SOLIDS, CONTACT_START, CpuStepper, cpu_backend};
pub use diagnosis::{Cause, Vibration, stiffest_vibration};
pub use effects::{
    AirDamping, BendingModel, ClothBox, ClothSprings, DEFAULT_DIHEDRAL_STIFFNESS, DEFAULT_FPS,
    Effect, FACE_TOUCHING, GROWTH, Gravity, Handle, ListedTwice, Obstacle, ObstacleError, Plane,
    Reach, SelfCollision, Sphere, TooThick, Wind, WindForce, air_damping_of, fitted_to_cloth,
    frame_path, gravity_of, listed_twice, min_surface_distance, obstacle_overlap_warnings,
    shortest_edge, thickness_fits,
};
pub use forces::{Force, ForceSet, ForceTerm, JacobianMode, SystemMatrix};
pub use guard::{
    Diverged, FrameOutcome, GuardAction, GuardEvent, GuardLimits, Motion, RESOLVED, Trouble, check,
    resolved,
};
pub use guard_policy::GuardPolicy;
pub use guard_state::{CpuSnapshot, GuardState, Snapshot};
pub use integrator::{Integrator, IntegratorKind, StepContext, StepError, StepMeter, StepReport};
pub use intersections::{Intersections, intersections};
pub use motion::{AxisAngle, Ease, Keyframe, MotionError, Pose, RigidMotion};
pub use param_error::ParamError;
pub use params::{Changes, ContactConfig, Material, SimParams, SolverConfig, StepConfig};
pub use precision::Precision;
pub use self_contacts::{
    ContactError, SELF_RECHECK, SELF_SETUP, SELF_UPKEEP, SelfContacts, SelfWork, owned_parts,
};
pub use stats::StepStats;
pub use timings::{Phase, PhaseTimings};
