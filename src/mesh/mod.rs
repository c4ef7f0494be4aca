//! Mesh import and topology: OBJ files and generated grids become [`ClothMesh`]es.

mod bounds;
mod error;
mod grid;
mod import;
mod normals;
mod obj;
mod polygons;
mod topology;
mod triangulate;
mod uv;
mod weld;

pub use bounds::{bbox_diagonal, bounds, thinnest_axis};
pub use error::ObjError;
pub use grid::{GridOrientation, GridSpec};
pub use import::{load_obj, obj_from_str};
pub use normals::vertex_normals;
pub use obj::{parse_obj, read_obj, write_obj};
pub use polygons::PolygonSoup;
pub use topology::{ClothMesh, MeshBuild, SpringKind, build_mesh};
pub use uv::planar_uvs;
