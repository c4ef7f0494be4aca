//! From a polygon soup to cloth topology: weld equal positions into particles, fan-triangulate
//! polygons, drop degenerate and duplicate triangles, and find the unique edges, the quads'
//! second diagonals and the bend pairs in `O(E log E)` by sorting.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::bounds::bbox_diagonal;
use super::error::ObjError;
use super::polygons::PolygonSoup;
use super::spring_kind::SpringKind;
use super::triangulate::{Triangulation, triangulate};
use super::uv::planar_uvs;
use super::weld::weld;

/// Cloth topology in its rest shape. Valid by construction: every particle belongs to at
/// least one triangle of positive area, indices are in range, edges are unique, and no
/// particle pair carries two springs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ClothMesh {
    /// Rest positions of the particles, metres.
    pub positions: Vec<Vec3>,
    /// One texture coordinate per particle.
    pub uvs: Vec<Vec2>,
    /// Triangles, counter-clockwise as in the source.
    pub triangles: Vec<[u32; 3]>,
    /// Unique edges of the triangulated mesh, `[a, b]` with `a < b`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// Kind of each edge: [`SpringKind::Structural`] or [`SpringKind::Shear`].
    pub edge_kinds: Vec<SpringKind>,
    /// The second diagonal of every quad (shear springs that are not mesh edges), sorted.
    pub cross_diagonals: Vec<[u32; 2]>,
    /// For each interior edge (exactly two triangles), its two opposite vertices; sorted,
    /// without repeats and without pairs that already are an edge or a diagonal.
    pub bend_pairs: Vec<[u32; 2]>,
    /// Every interior edge as a hinge `[x0, x1, a, b]`: the edge x0→x1 as it runs in
    /// triangle (x0, x1, a), and b, the vertex opposite in the other triangle. For dihedral
    /// bending.
    pub hinges: Vec<[u32; 4]>,
}

/// A built mesh plus what import had to drop or could not use.
#[derive(Clone, Debug)]
pub struct MeshBuild {
    pub mesh: ClothMesh,
    /// Human-readable notes, e.g. "dropped 2 zero-area triangles".
    pub warnings: Vec<String>,
}

/// A mesh built in code (a grid): nothing to warn about.
impl From<ClothMesh> for MeshBuild {
    fn from(mesh: ClothMesh) -> Self {
        Self {
            mesh,
            warnings: Vec::new(),
        }
    }
}

impl ClothMesh {
    /// `layers` copies of the mesh, each `step` (metres) beyond the one before, as one
    /// cloth of separate pieces (the copies share no particle).
    pub fn stacked(&self, layers: u32, step: Vec3) -> ClothMesh {
        let mut out = ClothMesh::default();
        let n = self.positions.len() as u32;
        for layer in 0..layers {
            let shift = step * layer as f32;
            let at = layer * n;
            let moved = |x: &[u32; 2]| x.map(|i| i + at);
            out.positions
                .extend(self.positions.iter().map(|&p| p + shift));
            out.uvs.extend_from_slice(&self.uvs);
            out.triangles
                .extend(self.triangles.iter().map(|t| t.map(|i| i + at)));
            out.edges.extend(self.edges.iter().map(moved));
            out.edge_kinds.extend_from_slice(&self.edge_kinds);
            out.cross_diagonals
                .extend(self.cross_diagonals.iter().map(moved));
            out.bend_pairs.extend(self.bend_pairs.iter().map(moved));
            out.hinges
                .extend(self.hinges.iter().map(|h| h.map(|i| i + at)));
        }
        out
    }

    /// Number of mesh edges of the given kind.
    pub fn edge_count(&self, kind: SpringKind) -> usize {
        self.edge_kinds.iter().filter(|&&k| k == kind).count()
    }

    /// Number of springs of the given kind (edges, quad diagonals and bend pairs).
    pub fn spring_count(&self, kind: SpringKind) -> usize {
        match kind {
            SpringKind::Structural => self.edge_count(kind),
            SpringKind::Shear => self.edge_count(kind) + self.cross_diagonals.len(),
            SpringKind::Bend => self.bend_pairs.len(),
        }
    }

    /// Every spring, in the model's order: edges, then quad diagonals, then bend pairs.
    pub fn springs(&self) -> impl Iterator<Item = ([u32; 2], SpringKind)> + '_ {
        let edges = self
            .edges
            .iter()
            .zip(&self.edge_kinds)
            .map(|(e, k)| (*e, *k));
        let diagonals = self.cross_diagonals.iter().map(|&d| (d, SpringKind::Shear));
        let bends = self.bend_pairs.iter().map(|&b| (b, SpringKind::Bend));
        edges.chain(diagonals).chain(bends)
    }
}

/// How import turns a polygon soup into a cloth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImportOptions {
    /// Corners closer than this fraction of the cloth's bounding-box diagonal weld into one
    /// particle (default 1e-6: a micrometre on a metre of cloth, far above f32 rounding and
    /// far below any real feature; 0 welds only identical positions).
    pub weld_tolerance: f32,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            weld_tolerance: 1e-6,
        }
    }
}

/// Builds the cloth topology from a polygon soup with the default [`ImportOptions`];
/// `source` names it in errors.
///
/// # Errors
/// [`ObjError::Empty`] when no triangle of positive area remains.
pub fn build_mesh(soup: &PolygonSoup, source: &Path) -> Result<MeshBuild, ObjError> {
    build_mesh_with(soup, source, &ImportOptions::default())
}

/// As [`build_mesh`], with `options`.
///
/// # Errors
/// [`ObjError::Empty`] when no triangle of positive area remains.
pub fn build_mesh_with(
    soup: &PolygonSoup,
    source: &Path,
    options: &ImportOptions,
) -> Result<MeshBuild, ObjError> {
    let welded = weld(soup, options.weld_tolerance);
    let scale = bbox_diagonal(&welded.positions).max(f32::MIN_POSITIVE);
    let mut tri = triangulate(
        &welded.positions,
        &welded.corners,
        &soup.face_arities,
        1e-10 * scale * scale,
    );
    let mut warnings = Vec::new();
    if tri.degenerate > 0 {
        warnings.push(format!(
            "dropped {} zero-area or collapsed triangle(s)",
            tri.degenerate
        ));
    }
    if tri.duplicate > 0 {
        warnings.push(format!("dropped {} duplicate triangle(s)", tri.duplicate));
    }
    if tri.triangles.is_empty() {
        return Err(ObjError::Empty {
            path: source.to_path_buf(),
            detail: format!("{} face(s), none with positive area", soup.face_count()),
        });
    }
    let (positions, mut uvs, unused) = compact(&welded.positions, &welded.uvs, &mut tri);
    if unused > 0 {
        warnings.push(format!(
            "dropped {unused} vertex/vertices used only by dropped triangles"
        ));
    }
    if soup.uvs.is_none() {
        uvs = planar_uvs(&positions);
    }
    let pieces = pieces(positions.len(), &tri.triangles);
    if pieces > 1 {
        warnings.push(format!(
            "the cloth is in {pieces} disconnected pieces, which move independently"
        ));
    }
    let links = links(&tri);
    if links.non_manifold > 0 {
        warnings.push(format!(
            "{} edge(s) shared by more than two triangles get no bending",
            links.non_manifold
        ));
    }
    Ok(MeshBuild {
        mesh: ClothMesh {
            positions,
            uvs,
            triangles: tri.triangles,
            edges: links.edges,
            edge_kinds: links.edge_kinds,
            cross_diagonals: links.cross_diagonals,
            bend_pairs: links.bend_pairs,
            hinges: links.hinges,
        },
        warnings,
    })
}

/// Number of connected pieces of `particles` joined by `triangles` (union–find).
fn pieces(particles: usize, triangles: &[[u32; 3]]) -> usize {
    let mut parent: Vec<u32> = (0..particles as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    for t in triangles {
        for pair in [[t[0], t[1]], [t[1], t[2]]] {
            let (a, b) = (root(&mut parent, pair[0]), root(&mut parent, pair[1]));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    (0..particles as u32)
        .filter(|&i| root(&mut parent, i) == i)
        .count()
}

/// Keeps only particles that a kept triangle uses, numbered in their order; returns
/// their positions, UVs and how many were dropped.
fn compact(
    positions: &[Vec3],
    uvs: &[Vec2],
    tri: &mut Triangulation,
) -> (Vec<Vec3>, Vec<Vec2>, usize) {
    let mut remap = vec![u32::MAX; positions.len()];
    for &i in tri.triangles.iter().flatten() {
        remap[i as usize] = 0;
    }
    let (mut kept_pos, mut kept_uv) = (Vec::new(), Vec::new());
    for (old, new) in remap.iter_mut().enumerate().filter(|(_, n)| **n == 0) {
        *new = kept_pos.len() as u32;
        kept_pos.push(positions[old]);
        kept_uv.push(uvs[old]);
    }
    for i in tri.triangles.iter_mut().flatten() {
        *i = remap[*i as usize];
    }
    for d in &mut tri.cross_diagonals {
        // Both corners belong to the quad's kept triangles, so both are mapped.
        let [a, b] = d.map(|i| remap[i as usize]);
        *d = [a.min(b), a.max(b)];
    }
    let unused = positions.len() - kept_pos.len();
    (kept_pos, kept_uv, unused)
}

/// Edges, diagonals and bend pairs, each sorted and free of pairs listed before it.
struct Links {
    edges: Vec<[u32; 2]>,
    edge_kinds: Vec<SpringKind>,
    cross_diagonals: Vec<[u32; 2]>,
    bend_pairs: Vec<[u32; 2]>,
    hinges: Vec<[u32; 4]>,
    non_manifold: usize,
}

/// Sorts the 3·T half-edges by vertex pair: each group is one unique edge; a group of two
/// with distinct opposite vertices is an interior edge and proposes a bend pair.
fn links(tri: &Triangulation) -> Links {
    // (low, high, kind, opposite, whether the triangle runs low → high)
    let mut half: Vec<(u32, u32, SpringKind, u32, bool)> =
        Vec::with_capacity(tri.triangles.len() * 3);
    for (t, sides) in tri.triangles.iter().zip(&tri.sides) {
        for s in 0..3 {
            let (a, b, opposite) = (t[s], t[(s + 1) % 3], t[(s + 2) % 3]);
            half.push((a.min(b), a.max(b), sides[s], opposite, a < b));
        }
    }
    half.sort_unstable();
    let (mut edges, mut edge_kinds, mut bends) = (Vec::new(), Vec::new(), Vec::new());
    let mut hinges = Vec::new();
    let mut non_manifold = 0usize;
    for group in half.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        edges.push([group[0].0, group[0].1]);
        // Sorting puts Structural first: an edge that is any polygon's side is structural.
        edge_kinds.push(group[0].2);
        match group {
            [_, _] if group[0].3 != group[1].3 => {
                let (p, q) = (group[0].3, group[1].3);
                bends.push([p.min(q), p.max(q)]);
                // Orient the hinge by a triangle that runs along the edge low → high.
                let (first, second) = if group[1].4 {
                    (group[1], group[0])
                } else {
                    (group[0], group[1])
                };
                let (x0, x1) = if first.4 {
                    (first.0, first.1)
                } else {
                    (first.1, first.0)
                };
                hinges.push([x0, x1, first.3, second.3]);
            }
            [_] | [_, _] => {}
            _ => non_manifold += 1,
        }
    }
    let mut cross_diagonals = tri.cross_diagonals.clone();
    cross_diagonals.sort_unstable();
    cross_diagonals.dedup();
    retain_absent(&mut cross_diagonals, &edges);
    bends.sort_unstable();
    bends.dedup();
    retain_absent(&mut bends, &edges);
    retain_absent(&mut bends, &cross_diagonals);
    Links {
        edges,
        edge_kinds,
        cross_diagonals,
        bend_pairs: bends,
        hinges,
        non_manifold,
    }
}

/// Keeps the pairs of sorted `v` that sorted `other` does not have: one merge-like pass
/// (a binary search per pair was a tenth of a 128 × 128 cloth's start-up).
fn retain_absent(v: &mut Vec<[u32; 2]>, other: &[[u32; 2]]) {
    let mut at = 0;
    v.retain(|x| {
        while other.get(at).is_some_and(|o| o < x) {
            at += 1;
        }
        other.get(at) != Some(x)
    });
}
