//! Effects are data: one type per effect, one file each, made variants of [`Effect`] by the
//! list in `registry.rs`. A scene lists the effects it uses and only those run.

mod air_damping;
mod bending;
mod between;
mod cloth_springs;
mod effect_kind;
mod faces;
mod gravity;
mod handle;
mod list;
mod obstacle;
mod plane;
mod reach;
mod registry;
mod self_collision;
mod solid;
mod sphere;
mod wind;

pub use air_damping::AirDamping;
pub use bending::{BendingModel, DEFAULT_DIHEDRAL_STIFFNESS};
pub use between::Between;
pub use cloth_springs::ClothSprings;
pub use effect_kind::{ClothBox, ContactPass, EffectKind, GuardShare};
pub use faces::FacePatches;
pub use gravity::Gravity;
pub use handle::Handle;
pub use list::{
    ListedTwice, air_damping_of, gravity_of, listed_twice, min_surface_distance,
    obstacle_overlap_warnings, thickness_fits,
};
pub use obstacle::{DEFAULT_FPS, Obstacle, ObstacleError, Placed, Shape, frame_path};
pub use plane::Plane;
pub use reach::{GROWTH, Reach, fitted_to_cloth};
#[cfg(test)]
pub(crate) use reach::{growing_cloth, rail, rising_roof};
pub use registry::{Addable, Effect};
pub use self_collision::{SelfCollision, TooThick, shortest_edge};
pub use sphere::{FACE_TOUCHING, Sphere};
pub use wind::{Wind, WindForce};
