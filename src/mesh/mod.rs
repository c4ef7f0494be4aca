//! Mesh import and topology: OBJ files and generated grids become [`ClothMesh`]es.

mod error;
mod grid;
mod normals;
mod obj;
mod polygons;
mod topology;
mod uv;

pub use error::ObjError;
pub use grid::{GridOrientation, GridSpec};
pub use normals::vertex_normals;
pub use obj::{parse_obj, read_obj, write_obj};
pub use polygons::PolygonSoup;
pub use topology::{ClothMesh, MeshBuild, SpringKind, bounds, build_mesh, thinnest_axis};
pub use uv::planar_uvs;

use std::path::Path;

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

impl GridSpec {
    /// The grid's cloth topology (identical to importing [`GridSpec::to_obj`]).
    ///
    /// # Errors
    /// [`ObjError::Empty`] when a size is zero or not finite.
    pub fn build(&self) -> Result<ClothMesh, ObjError> {
        Ok(build_mesh(&self.polygons(), Path::new("<grid>"))?.mesh)
    }
}
