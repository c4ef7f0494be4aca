//! Mesh import and topology: OBJ files and generated grids become [`ClothMesh`]es.

mod bounds;
mod error;
mod grid;
mod import;
mod incidence;
mod limits;
mod normals;
mod obj;
mod pick;
mod polygons;
mod read;
mod spring_kind;
mod topology;
mod triangulate;
mod uv;
mod validate;
mod weld;

pub use bounds::{bbox_diagonal, bounds, thinnest_axis};
pub use error::ObjError;
pub use grid::{GridBends, GridOrientation, GridSpec};
pub use import::{load_obj, load_obj_with, obj_from_str, obj_from_str_with};
pub use incidence::{grouped, triangles_around};
pub use limits::{MAX_COORDINATE, MAX_FILE_BYTES, MAX_TRIANGLES, MAX_VERTICES};
pub use normals::vertex_normals;
pub use obj::{parse_obj, write_obj};
pub use pick::{Hit, pick};
pub use polygons::PolygonSoup;
pub use read::read_obj;
pub use spring_kind::SpringKind;
pub use topology::{ClothMesh, ImportOptions, MeshBuild, build_mesh, build_mesh_with};
pub use uv::planar_uvs;
