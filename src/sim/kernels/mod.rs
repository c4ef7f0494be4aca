//! How fast: the vectorised, block-parallel loops the force terms and solvers call. The
//! physics files say what they compute; these say how it is laid out and shared between
//! threads.

mod components;
mod elements;
#[cfg(target_arch = "x86_64")]
mod lanes;
mod points;
mod run_pass;
mod spring_runs;
mod two_passes;
mod vbd_lanes;
mod vbd_stencil;
mod vec3x8;
mod xpbd_lanes;

pub use crate::cloth::Real;
pub use components::{
    Blocks, Components, Scratch, at, blocks_times, blocks_times_in, join, split, zeroed,
};
pub use elements::{ElementForces, NOTHING, Slots};
pub use points::{leaves, less_into, outside, take_changes, take_moves};
pub use run_pass::Projectors;
pub use spring_runs::{SpringRuns, SystemSums};
pub use two_passes::{BlockPass, TwoPasses};
pub use vbd_lanes::{Particle, StepLength, descend_range, descend_range_plain};
pub use vbd_stencil::Stencil;
pub use vec3x8::{LANES, Vec3x8, padded};
pub use xpbd_lanes::{Moved, Scaled, project_range, project_range_plain};
