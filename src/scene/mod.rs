//! Scenes: the scenario registry, scene construction, and the running simulation.

mod error;
mod framing;
mod registry;
#[allow(clippy::module_inception)]
mod scene;
mod simulation;
mod summary;

pub use error::SceneError;
pub use registry::{PinRule, SCENARIOS, Scenario, ScenarioSetup, scenario};
pub use scene::{DEFAULT_CLOTH_NAME, DEFAULT_CLOTH_OBJ, Scene};
pub use simulation::Simulation;
pub use summary::RunSummary;
