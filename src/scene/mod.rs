//! Scenes: the scenario registry, scene construction, and the running simulation.

mod error;
mod file;
mod framing;
mod locate;
mod registry;
mod resize;
mod save;
#[allow(clippy::module_inception)]
mod scene;
mod simulation;
mod summary;

pub use error::{PinError, SceneError};
pub use file::{
    ClothSpec, Corner, Edge, GridShape, HandleSpec, LoadedSceneFile, MaterialSpec, OneOrTwo,
    PerKind, PinSpec, Region, SceneFile, SolverSpec,
};
pub use registry::{BUILTIN_SCENES, scenario, scenarios};
pub use save::{SaveError, Saved};
pub use scene::{DEFAULT_CLOTH_NAME, DEFAULT_CLOTH_OBJ, Scene};
pub use simulation::{GRAB_WINDOW, Simulation};
pub use summary::{PhaseSummary, RunSummary};
