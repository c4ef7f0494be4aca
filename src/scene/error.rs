//! Errors of building a scene or changing a running simulation.

use crate::mesh::ObjError;

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error(transparent)]
    Obj(#[from] ObjError),
    #[error("unknown scenario `{name}`; available: {available}")]
    UnknownScenario { name: String, available: String },
    /// A parameter set was refused; the simulation keeps the parameters it had.
    #[error("{0}; the previous parameters are kept")]
    Params(String),
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
    /// A self-collision thickness the cloth cannot take (at or above its shortest rest
    /// edge); `cloth` names the cloth.
    #[error("{cloth}: {error}")]
    Thickness {
        cloth: String,
        error: crate::sim::TooThick,
    },
    /// The pins do not fit the cloth.
    #[error("{0}")]
    Pins(String),
    /// The step backend cannot run the scene (or could not start).
    #[error("{0}")]
    Backend(String),
}
