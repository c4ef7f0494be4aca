//! OBJ text or files to cloth topology in one call.

use std::path::Path;

use super::error::ObjError;
use super::obj::{parse_obj, read_obj};
use super::topology::{MeshBuild, build_mesh};

/// Loads an OBJ file and builds its cloth topology.
///
/// # Errors
/// Any [`ObjError`]: file problems, bad content, or no usable triangle.
pub fn load_obj(path: &Path) -> Result<MeshBuild, ObjError> {
    build_mesh(&read_obj(path)?, path)
}

/// Builds the topology of OBJ text; `name` stands for the file in messages.
///
/// # Errors
/// As [`load_obj`], less the file-system errors.
pub fn obj_from_str(text: &str, name: &str) -> Result<MeshBuild, ObjError> {
    let path = Path::new(name);
    build_mesh(&parse_obj(text, path)?, path)
}
