//! Errors of building a scene.

use crate::mesh::ObjError;

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error(transparent)]
    Obj(#[from] ObjError),
    #[error("unknown scenario `{name}`; available: {available}")]
    UnknownScenario { name: String, available: String },
    #[error("invalid parameters: {0}")]
    Params(String),
}
