//! Cloth model (static) and state (per step).

mod adjacency;
mod model;
mod state;

pub use adjacency::Adjacency;
pub use model::{ClothModel, MASS_FLOOR, MassDistribution, Springs};
pub use state::ClothState;
