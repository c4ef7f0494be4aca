//! Force terms and their derivatives: what every term computes ([`ForceTerm`]), the springs
//! and the dihedral hinges (the other terms are their effects' types in `sim/effects`), and
//! [`ForceSet`], which evaluates a scene's terms together and is the one place forces become
//! accelerations.

mod dihedral;
mod force;
mod force_set;
mod force_term;
mod jacobian;
mod springs;
mod system_springs;

pub use dihedral::{DihedralBending, hinge_angle};
pub use force::Force;
pub use force_set::{ForceSet, TermTimes, to_accelerations};
pub use force_term::{ForceTerm, Fused};
pub use jacobian::{JacobianMode, SystemMatrix};
pub use springs::{SpringBlocks, SpringForce};
pub use system_springs::SpringBlock;

#[cfg(test)]
mod derivative_tests;
