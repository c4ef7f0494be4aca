//! OBJ text or files to cloth topology in one call.

use std::path::Path;

use super::error::ObjError;
use super::obj::parse_obj;
use super::read::read_obj;
use super::topology::{ImportOptions, MeshBuild, build_mesh_with};

/// Loads an OBJ file and builds its cloth topology with the default [`ImportOptions`].
///
/// # Errors
/// Any [`ObjError`]: file problems, bad content, or no usable triangle.
pub fn load_obj(path: &Path) -> Result<MeshBuild, ObjError> {
    load_obj_with(path, &ImportOptions::default())
}

/// As [`load_obj`], with `options`.
///
/// # Errors
/// As [`load_obj`].
pub fn load_obj_with(path: &Path, options: &ImportOptions) -> Result<MeshBuild, ObjError> {
    build_mesh_with(&read_obj(path)?, path, options)
}

/// Builds the topology of OBJ text; `name` stands for the file in messages.
///
/// # Errors
/// As [`load_obj`], less the file-system errors.
pub fn obj_from_str(text: &str, name: &str) -> Result<MeshBuild, ObjError> {
    obj_from_str_with(text, name, &ImportOptions::default())
}

/// As [`obj_from_str`], with `options`.
///
/// # Errors
/// As [`obj_from_str`].
pub fn obj_from_str_with(
    text: &str,
    name: &str,
    options: &ImportOptions,
) -> Result<MeshBuild, ObjError> {
    let path = Path::new(name);
    build_mesh_with(&parse_obj(text, path)?, path, options)
}
