//! An obstacle's tips: the vertices where its faces meet at a point rather than along a
//! flat or gently curved surface (a pyramid's apex, a table's corners, the rim of a drum),
//! which can poke through a cloth triangle whose particles and edges all keep clear of
//! the faces and the sharp edges.

use std::collections::HashMap;

use glam::Vec3;

use super::edges::CREASE_COS;
use super::tree::TriangleTree;

/// The tips of a surface and a tree over them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tips {
    /// Each tip's vertex, and where it is.
    vertices: Vec<u32>,
    points: Vec<Vec3>,
    tree: TriangleTree,
}

impl Tips {
    /// The vertices of `triangles` over `vertices` that end a sharp edge (`sharp`: each
    /// sharp edge's two vertices) or whose faces' normals (`normals`, per triangle) differ
    /// somewhere by more than about 10°, as a sharp edge's do. Vertices at the same place
    /// are one vertex (a surface written with its faces apart has its tips where its faces
    /// bend), and a degenerate face (zero normal) says nothing.
    pub fn of(
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        normals: &[Vec3],
        sharp: impl IntoIterator<Item = [u32; 2]>,
    ) -> Self {
        // The bits of each coordinate, −0 as +0.
        let place = |v: &Vec3| v.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() });
        let mut first_at: HashMap<[u32; 3], u32> = HashMap::with_capacity(vertices.len());
        let same: Vec<u32> = (vertices.iter().enumerate())
            .map(|(i, v)| *first_at.entry(place(v)).or_insert(i as u32))
            .collect();
        let mut tip = vec![false; vertices.len()];
        for [a, b] in sharp {
            tip[same[a as usize] as usize] = true;
            tip[same[b as usize] as usize] = true;
        }
        // Each vertex's faces, by vertex.
        let mut faces: Vec<(u32, u32)> = (triangles.iter().enumerate())
            .filter(|&(t, _)| normals[t] != Vec3::ZERO)
            .flat_map(|(t, tri)| tri.map(|i| (same[i as usize], t as u32)))
            .collect();
        faces.sort_unstable();
        for fan in faces.chunk_by(|a, b| a.0 == b.0) {
            let v = fan[0].0 as usize;
            if tip[v] {
                continue;
            }
            let spread = |&(_, s): &(u32, u32)| {
                let n = normals[s as usize];
                (fan.iter()).any(|&(_, t)| n.dot(normals[t as usize]).abs() < CREASE_COS)
            };
            tip[v] = fan.iter().any(spread);
        }
        let ids: Vec<u32> = (0..vertices.len() as u32)
            .filter(|&v| tip[v as usize])
            .collect();
        let points: Vec<Vec3> = ids.iter().map(|&v| vertices[v as usize]).collect();
        Self {
            tree: TriangleTree::new(&points.iter().map(|&p| [p; 3]).collect::<Vec<_>>()),
            vertices: ids,
            points,
        }
    }

    /// The same tips over moved `vertices` (which vertices are tips stays as first found).
    pub fn refit(&mut self, vertices: &[Vec3]) {
        for (point, &v) in self.points.iter_mut().zip(&self.vertices) {
            *point = vertices[v as usize];
        }
        let points = &self.points;
        self.tree.refit(|k| [points[k]; 3]);
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Calls `visit` with every tip in the box `lo..hi`.
    pub fn in_box(&self, lo: Vec3, hi: Vec3, mut visit: impl FnMut(Vec3)) {
        self.tree
            .overlapping(lo, hi, |k| visit(self.points[k as usize]));
    }

    /// Whether a tip lies in the box `lo..hi`.
    pub fn any_in_box(&self, lo: Vec3, hi: Vec3) -> bool {
        let mut any = false;
        self.tree.overlapping_while(lo, hi, |_| {
            any = true;
            false
        });
        any
    }

    /// The box around every tip (`None` for none).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.tree.bounds()
    }
}

#[cfg(test)]
mod tests;
