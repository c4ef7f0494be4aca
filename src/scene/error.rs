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
}
