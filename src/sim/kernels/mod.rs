//! How fast: the vectorised, block-parallel loops the force terms and solvers call. The
//! physics files say what they compute; these say how it is laid out and shared between
//! threads.

mod components;
mod real;
mod run_pass;
mod spring_runs;
mod two_passes;
mod xpbd_lanes;

pub use components::{
    Blocks, Components, Scratch, blocks_times, join, split, split_blocks, zeroed,
};
pub use real::Real;
pub use run_pass::Projectors;
pub use spring_runs::SpringRuns;
pub use two_passes::{BlockPass, TwoPasses};
pub use xpbd_lanes::{Moved, Scaled, project_range};
