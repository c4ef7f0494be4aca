//! Cloth model (static) and state (per step).

mod adjacency;
mod edge_colours;
mod model;
mod real;
mod springs;
mod state;

pub use adjacency::Adjacency;
pub use edge_colours::{EdgeColours, colour_greedily};
pub use model::{ClothModel, MASS_FLOOR, MassDistribution};
pub use real::{Matrix, Real, Vector};
pub use springs::Springs;
pub use state::ClothState;
