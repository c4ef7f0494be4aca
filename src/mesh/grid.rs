//! Rectangular grid generator: the same polygons a quad OBJ of the grid would hold.

use glam::{Vec2, Vec3};

use std::path::Path;

use super::error::ObjError;
use super::polygons::PolygonSoup;
use super::topology::{ClothMesh, build_mesh};

/// The plane a generated grid lies in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GridOrientation {
    /// Horizontal: x to the right, z towards the viewer (normal +y). For draping scenes.
    Horizontal,
    /// Vertical: x to the right, y up (normal +z). For hanging scenes.
    Vertical,
}

/// Which particle pairs of a grid get bend springs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GridBends {
    /// The two vertices opposite each interior edge (as for any imported mesh).
    #[default]
    AcrossEdges,
    /// Every particle to the one two steps along its row and its column (Provot's flexion
    /// springs, the 12-neighbour stencil's `(2,0)` and `(0,2)`).
    SkipOne,
}

/// A grid of `quads_x × quads_y` quads, `size_x × size_y` metres, centred on `center`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    pub quads_x: u32,
    pub quads_y: u32,
    /// Extent along the first axis, metres.
    pub size_x: f32,
    /// Extent along the second axis, metres.
    pub size_y: f32,
    pub orientation: GridOrientation,
    pub center: Vec3,
}

impl GridSpec {
    /// A square grid of `n × n` quads, `size` metres wide.
    pub fn square(n: u32, size: f32, orientation: GridOrientation, center: Vec3) -> Self {
        Self {
            quads_x: n,
            quads_y: n,
            size_x: size,
            size_y: size,
            orientation,
            center,
        }
    }

    /// Builds the polygon soup: `(quads_x+1) × (quads_y+1)` vertices in row-major order
    /// (row 0 first; for a vertical grid row 0 is the top), one quad per cell wound
    /// counter-clockwise seen from the normal side, UVs spanning `[0, 1]²`.
    pub fn polygons(&self) -> PolygonSoup {
        let (nx, ny) = (self.quads_x.max(1), self.quads_y.max(1));
        let mut positions = Vec::with_capacity(((nx + 1) * (ny + 1)) as usize);
        let mut uvs = Vec::with_capacity(positions.capacity());
        for j in 0..=ny {
            for i in 0..=nx {
                let u = i as f32 / nx as f32;
                let v = j as f32 / ny as f32;
                let a = (u - 0.5) * self.size_x;
                let b = (v - 0.5) * self.size_y;
                let local = match self.orientation {
                    // Row 0 at the back (-z), rows advance towards +z.
                    GridOrientation::Horizontal => Vec3::new(a, 0.0, b),
                    // Row 0 at the top (+y), rows advance downwards.
                    GridOrientation::Vertical => Vec3::new(a, -b, 0.0),
                };
                positions.push(self.center + local);
                uvs.push(Vec2::new(u, v));
            }
        }
        let row = nx + 1;
        let mut face_indices = Vec::with_capacity((nx * ny * 4) as usize);
        for j in 0..ny {
            for i in 0..nx {
                let v00 = j * row + i;
                let v10 = v00 + 1;
                let v01 = v00 + row;
                let v11 = v01 + 1;
                // Counter-clockwise seen from +y (horizontal) and from +z (vertical).
                face_indices.extend_from_slice(&[v00, v01, v11, v10]);
            }
        }
        PolygonSoup {
            positions,
            uvs: Some(uvs),
            face_indices,
            face_arities: vec![4; (nx * ny) as usize],
        }
    }

    /// The grid as OBJ text (one `v` and `vt` per vertex, one quad `f` per cell).
    pub fn to_obj(&self) -> String {
        super::obj::write_obj(&self.polygons())
    }

    /// The grid's cloth topology (identical to importing [`GridSpec::to_obj`]).
    ///
    /// # Errors
    /// [`ObjError::Empty`] when a size is zero or not finite.
    pub fn build(&self) -> Result<ClothMesh, ObjError> {
        Ok(build_mesh(&self.polygons(), Path::new("<grid>"))?.mesh)
    }

    /// The grid's topology with bend springs chosen by `bends`.
    ///
    /// # Errors
    /// As [`GridSpec::build`].
    pub fn build_with(&self, bends: GridBends) -> Result<ClothMesh, ObjError> {
        let soup = self.polygons();
        let mut mesh = build_mesh(&soup, Path::new("<grid>"))?.mesh;
        if bends == GridBends::SkipOne {
            // Find each grid vertex's particle by its (exactly kept) position: the
            // numbering is welding's business.
            let key = |p: Vec3| p.to_array().map(f32::to_bits);
            let particle: rustc_hash::FxHashMap<[u32; 3], u32> = mesh
                .positions
                .iter()
                .enumerate()
                .map(|(i, &p)| (key(p), i as u32))
                .collect();
            let id = |k: u32| particle.get(&key(soup.positions[k as usize])).copied();
            let (nx, ny) = (self.quads_x.max(1), self.quads_y.max(1));
            let row = nx + 1;
            let mut pairs = Vec::new();
            for j in 0..=ny {
                for i in 0..=nx {
                    let k = j * row + i;
                    let right = (i + 2 <= nx).then_some(k + 2);
                    let down = (j + 2 <= ny).then_some(k + 2 * row);
                    for other in [right, down].into_iter().flatten() {
                        if let (Some(a), Some(b)) = (id(k), id(other)) {
                            pairs.push([a.min(b), a.max(b)]);
                        }
                    }
                }
            }
            pairs.sort_unstable();
            mesh.bend_pairs = pairs;
        }
        Ok(mesh)
    }
}
