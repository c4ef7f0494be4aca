//! Force terms (one file each) and their derivatives; [`ForceSet`] evaluates a scene's terms
//! together and is the one place forces become accelerations.

mod air_damping;
mod dihedral;
mod force;
mod force_set;
mod gravity;
mod jacobian;
mod springs;
mod wind;

pub use air_damping::AirDamping;
pub use dihedral::{DihedralBending, hinge_angle};
pub use force::Force;
pub use force_set::{ForceSet, TermTimes, to_accelerations};
pub use gravity::Gravity;
pub use jacobian::{JacobianMode, SpringBlock, SystemMatrix, SystemProduct};
pub use springs::{SpringBlocks, SpringForce};
pub use wind::Wind;

#[cfg(test)]
mod derivative_tests;
