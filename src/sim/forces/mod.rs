//! Force terms (one file each) and their derivatives; [`ForceSet`] evaluates a scene's terms
//! together and is the one place forces become accelerations.

mod air_damping;
mod force;
mod force_set;
mod gravity;
mod jacobian;
mod springs;

pub use air_damping::AirDamping;
pub use force::Force;
pub use force_set::{ForceSet, to_accelerations};
pub use gravity::Gravity;
pub use jacobian::{JacobianMode, SystemMatrix};
pub use springs::{SpringBlocks, SpringForce};

#[cfg(test)]
mod derivative_tests;
