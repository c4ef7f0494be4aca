//! Errors of building a scene or changing a running simulation.

use glam::Vec3;

use crate::mesh::ObjError;
use crate::sim::ParamError;

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error(transparent)]
    Obj(#[from] ObjError),
    #[error("unknown scenario `{name}`; available: {available}")]
    UnknownScenario { name: String, available: String },
    /// A parameter set was refused; the simulation keeps the parameters it had.
    #[error("{0}; the previous parameters are kept")]
    Params(#[from] ParamError),
    /// A scene file could not be read.
    #[error("{path}: cannot read the scene file: {detail}")]
    Read {
        path: std::path::PathBuf,
        detail: String,
    },
    /// A scene file has a problem at a line and column.
    #[error("{path}:{line}:{column}: {message}")]
    File {
        path: std::path::PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// An effect's value out of range; the simulation keeps the effects it had.
    #[error("`{effect}`: {error}; the previous effects are kept")]
    Effect {
        effect: &'static str,
        error: ParamError,
    },
    /// A self-collision thickness the cloth cannot take (at or above its shortest rest
    /// edge); `cloth` names the cloth.
    #[error("{cloth}: {error}")]
    Thickness {
        cloth: String,
        error: crate::sim::TooThick,
    },
    /// The pins do not fit the cloth.
    #[error(transparent)]
    Pins(#[from] PinError),
    /// An obstacle's mesh could not be read or placed.
    #[error(transparent)]
    Obstacle(#[from] crate::sim::ObstacleError),
    /// `--quads` cannot resize this scene's cloth.
    #[error("scene `{scene}`: {why}")]
    Resize { scene: String, why: String },
    /// A scene file built in code names no cloth (`cloth.obj` or `cloth.grid`).
    #[error("the scene `{scene}` has no cloth: give `obj` or `grid` in [cloth]")]
    NoCloth { scene: String },
}

/// Pins that do not fit the cloth.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PinError {
    #[error("pin index {index} does not exist: the cloth has {particles} particles")]
    NoSuchParticle { index: u32, particles: usize },
    /// A handle whose rules choose no particle (`handle` counts from 1, as in the file).
    #[error("handle {handle} chooses no particle")]
    EmptyHandle { handle: usize },
    /// A particle both in a handle and in `[pins]`: it cannot both stay and move.
    #[error(
        "particle {particle} is both in handle {handle} and in [pins]; it cannot both stay and move"
    )]
    PinnedAndHandled { handle: usize, particle: u32 },
    /// An empty region is a mistake (a typo in a bound), not a wish for no pins.
    #[error("the pin region from {min} to {max} holds no particle: the cloth spans {lo} to {hi}")]
    EmptyRegion {
        min: Vec3,
        max: Vec3,
        lo: Vec3,
        hi: Vec3,
    },
}
