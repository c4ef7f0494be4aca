//! An obstacle's tips: the vertices where its faces meet at a point rather than along a
//! flat or gently curved surface (a pyramid's apex, a table's corners, the rim of a drum),
//! which can poke through a cloth triangle whose particles and edges all keep clear of
//! the faces and the sharp edges.

use glam::Vec3;

use super::edges::CREASE_COS;
use super::geometry::welded;
use super::tree::TriangleTree;

/// The tips of a surface and a tree over them; and the rest of its vertices (its smooth
/// parts'), with a tree, and how sharply those parts curve at most.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tips {
    tips: Points,
    smooth: Points,
    /// The largest curvature of the smooth parts, 1/m: at each smooth vertex, the angle
    /// between the two of its faces that turn most from each other over the distance
    /// between their centroids (an estimate: a sliver's centroid lies off its normal's
    /// point, and a cube-sphere's corners read three times their true curvature).
    curvature: f32,
}

/// Some vertices of a surface, where they are, and a tree over them; for the smooth
/// vertices, each one's curvature too (1/m; none for the tips).
#[derive(Clone, Debug, Default, PartialEq)]
struct Points {
    vertices: Vec<u32>,
    points: Vec<Vec3>,
    curvatures: Vec<f32>,
    tree: TriangleTree,
}

impl Points {
    fn of(ids: Vec<u32>, curvatures: Vec<f32>, vertices: &[Vec3]) -> Self {
        let points: Vec<Vec3> = ids.iter().map(|&v| vertices[v as usize]).collect();
        Points {
            tree: TriangleTree::new(&points.iter().map(|&p| [p; 3]).collect::<Vec<_>>()),
            vertices: ids,
            points,
            curvatures,
        }
    }

    fn refit(&mut self, vertices: &[Vec3]) {
        for (point, &v) in self.points.iter_mut().zip(&self.vertices) {
            *point = vertices[v as usize];
        }
        let points = &self.points;
        self.tree.refit(|k| [points[k]; 3]);
    }

    fn in_box(&self, lo: Vec3, hi: Vec3, mut visit: impl FnMut(Vec3)) {
        self.tree
            .overlapping(lo, hi, |k| visit(self.points[k as usize]));
    }
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
        Self::of_or(vertices, triangles, normals, sharp, |_| false)
    }

    /// As [`Tips::of`], and also every vertex that `also` says is one (given the vertex,
    /// welded: the first at its place).
    pub fn of_or(
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        normals: &[Vec3],
        sharp: impl IntoIterator<Item = [u32; 2]>,
        also: impl Fn(u32) -> bool,
    ) -> Self {
        let same = welded(vertices);
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
        let (mut smooth, mut curvatures) = (Vec::new(), Vec::new());
        let centroid = |t: u32| {
            triangles[t as usize]
                .map(|i| vertices[i as usize])
                .iter()
                .sum::<Vec3>()
                / 3.0
        };
        for fan in faces.chunk_by(|a, b| a.0 == b.0) {
            let v = fan[0].0;
            if tip[v as usize] {
                continue;
            }
            // The two faces that turn most from each other.
            let mut most = (1.0f32, fan[0].1, fan[0].1);
            for (k, &(_, s)) in fan.iter().enumerate() {
                for &(_, t) in &fan[k + 1..] {
                    let cos = normals[s as usize].dot(normals[t as usize]).abs();
                    if cos < most.0 {
                        most = (cos, s, t);
                    }
                }
            }
            if most.0 < CREASE_COS || also(v) {
                tip[v as usize] = true;
                continue;
            }
            smooth.push(v);
            let apart = centroid(most.1).distance(centroid(most.2));
            let turn = most.0.clamp(0.0, 1.0).acos();
            curvatures.push(if apart > 0.0 { turn / apart } else { 0.0 });
        }
        let ids: Vec<u32> = (0..vertices.len() as u32)
            .filter(|&v| tip[v as usize])
            .collect();
        let curvature = curvatures.iter().copied().fold(0.0, f32::max);
        Self {
            tips: Points::of(ids, Vec::new(), vertices),
            smooth: Points::of(smooth, curvatures, vertices),
            curvature,
        }
    }

    /// The same tips and smooth vertices over moved `vertices` (which vertices are tips,
    /// and the curvature, stay as first found).
    pub fn refit(&mut self, vertices: &[Vec3]) {
        self.tips.refit(vertices);
        self.smooth.refit(vertices);
    }

    /// Whether the vertex `v` (welded: the first at its place) is a tip.
    pub fn has(&self, v: u32) -> bool {
        self.tips.vertices.binary_search(&v).is_ok()
    }

    /// The tips' vertices (welded: each the first at its place), in order.
    pub fn vertices(&self) -> &[u32] {
        &self.tips.vertices
    }

    /// These tips, each smooth vertex's curvature raised to the largest it has among
    /// `others` (the same surface elsewhere: a sequence's other frames) where it is smooth
    /// there too.
    pub fn curving_as_much_as<'t>(mut self, others: impl IntoIterator<Item = &'t Tips>) -> Self {
        for other in others {
            let (theirs, curvatures) = (&other.smooth.vertices, &other.smooth.curvatures);
            let ours = self.smooth.vertices.iter();
            for (v, k) in ours.zip(&mut self.smooth.curvatures) {
                if let Ok(i) = theirs.binary_search(v) {
                    *k = k.max(curvatures[i]);
                }
            }
        }
        self.curvature = self.smooth.curvatures.iter().copied().fold(0.0, f32::max);
        self
    }

    /// How many tips.
    pub fn len(&self) -> usize {
        self.tips.points.len()
    }

    /// No tips, and no smooth vertices either.
    pub fn is_empty(&self) -> bool {
        self.tips.points.is_empty() && self.smooth.points.is_empty()
    }

    /// Calls `visit` with every tip in the box `lo..hi`.
    pub fn in_box(&self, lo: Vec3, hi: Vec3, visit: impl FnMut(Vec3)) {
        self.tips.in_box(lo, hi, visit);
    }

    /// Calls `visit` with every smooth vertex in the box `lo..hi` and its curvature (1/m).
    pub fn smooth_in_box(&self, lo: Vec3, hi: Vec3, mut visit: impl FnMut(Vec3, f32)) {
        let smooth = &self.smooth;
        (smooth.tree).overlapping(lo, hi, |k| {
            visit(smooth.points[k as usize], smooth.curvatures[k as usize])
        });
    }

    /// The tips' tree, and the smooth vertices' with each one's curvature (1/m, by the
    /// number the tree holds it under): as the GPU takes them.
    pub fn trees(&self) -> (&TriangleTree, &TriangleTree, &[f32]) {
        (&self.tips.tree, &self.smooth.tree, &self.smooth.curvatures)
    }

    /// The largest curvature of the smooth parts, 1/m (see [`Tips`]).
    pub fn curvature(&self) -> f32 {
        self.curvature
    }

    /// Whether a tip lies in the box `lo..hi`, or (`smooth`) any vertex.
    pub fn any_in_box(&self, lo: Vec3, hi: Vec3, smooth: bool) -> bool {
        let any = |points: &Points| {
            let mut found = false;
            points.tree.overlapping_while(lo, hi, |_| {
                found = true;
                false
            });
            found
        };
        any(&self.tips) || (smooth && any(&self.smooth))
    }
}

#[cfg(test)]
mod tests;
