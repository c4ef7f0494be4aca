//! The common input of the topology builder: positions plus polygons, as an OBJ file
//! or the grid generator describes them.

use glam::{Vec2, Vec3};

/// A polygon soup: positions (possibly repeated) and faces as index lists of any arity ≥ 3.
///
/// Faces are stored flat: `face_indices` holds the corners of every face one after the
/// other and `face_arities[i]` says how many belong to face `i`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolygonSoup {
    /// Corner positions in metres.
    pub positions: Vec<Vec3>,
    /// Texture coordinates per position index, when the source has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Corners of all faces, flat, indexing `positions`.
    pub face_indices: Vec<u32>,
    /// Number of corners of each face.
    pub face_arities: Vec<u32>,
}

impl PolygonSoup {
    /// Iterates over the faces as slices of position indices.
    pub fn faces(&self) -> impl Iterator<Item = &[u32]> {
        let mut start = 0usize;
        self.face_arities.iter().map(move |&n| {
            let face = &self.face_indices[start..start + n as usize];
            start += n as usize;
            face
        })
    }

    /// Number of faces.
    pub fn face_count(&self) -> usize {
        self.face_arities.len()
    }

    /// The same surface with every polygon fan-split into triangles (corner 0, k, k+1).
    pub fn triangulated(&self) -> PolygonSoup {
        let mut face_indices = Vec::with_capacity(self.face_indices.len() * 2);
        for face in self.faces() {
            for k in 1..face.len() - 1 {
                face_indices.extend_from_slice(&[face[0], face[k], face[k + 1]]);
            }
        }
        PolygonSoup {
            positions: self.positions.clone(),
            uvs: self.uvs.clone(),
            face_arities: vec![3; face_indices.len() / 3],
            face_indices,
        }
    }
}
