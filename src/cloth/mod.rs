//! Cloth model (static) and state (per step).

mod model;
mod state;

pub use model::{ClothModel, Springs};
pub use state::ClothState;
