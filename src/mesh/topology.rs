//! From a polygon soup to cloth topology: weld equal positions into particles, fan-triangulate
//! polygons (diagonals become shear edges), drop degenerate and duplicate triangles, and find
//! the unique edges and bend pairs in `O(E log E)` by sorting.

use std::collections::HashMap;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::error::ObjError;
use super::polygons::PolygonSoup;
use super::uv::planar_uvs;

/// What a spring models. Mesh edges are structural (polygon sides) or shear (diagonals added
/// by triangulating quads and n-gons); a bend spring joins the two vertices opposite an
/// interior edge.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
pub enum SpringKind {
    Structural,
    Shear,
    Bend,
}

impl SpringKind {
    /// All kinds, in the order per-kind parameter arrays use.
    pub const ALL: [SpringKind; 3] = [SpringKind::Structural, SpringKind::Shear, SpringKind::Bend];

    /// Index into per-kind parameter arrays.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Lower-case name for tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            SpringKind::Structural => "structural",
            SpringKind::Shear => "shear",
            SpringKind::Bend => "bend",
        }
    }
}

/// Cloth topology in its rest shape. Valid by construction: every particle belongs to at
/// least one triangle of positive area, indices are in range, edges are unique.
#[derive(Clone, Debug, PartialEq)]
pub struct ClothMesh {
    /// Rest positions of the particles, metres.
    pub positions: Vec<Vec3>,
    /// One texture coordinate per particle.
    pub uvs: Vec<Vec2>,
    /// Triangles, counter-clockwise as in the source.
    pub triangles: Vec<[u32; 3]>,
    /// Unique mesh edges `[a, b]` with `a < b`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// Kind of each edge: [`SpringKind::Structural`] or [`SpringKind::Shear`].
    pub edge_kinds: Vec<SpringKind>,
    /// For each interior edge (exactly two triangles), its two opposite vertices.
    pub bend_pairs: Vec<[u32; 2]>,
}

/// A built mesh plus what import had to drop or could not use.
#[derive(Clone, Debug)]
pub struct MeshBuild {
    pub mesh: ClothMesh,
    /// Human-readable notes, e.g. "dropped 2 zero-area triangles".
    pub warnings: Vec<String>,
}

/// Exact position key: equal coordinates weld (−0 and +0 count as equal).
fn weld_key(p: Vec3) -> [u32; 3] {
    let bits = |x: f32| if x == 0.0 { 0 } else { x.to_bits() };
    [bits(p.x), bits(p.y), bits(p.z)]
}

/// Builds the cloth topology from a polygon soup; `source` names it in errors.
///
/// # Errors
/// [`ObjError::Empty`] when no triangle of positive area remains.
pub fn build_mesh(soup: &PolygonSoup, source: &Path) -> Result<MeshBuild, ObjError> {
    let mut warnings = Vec::new();

    // 1. Weld corners by exact position, numbering welded points in first-use order.
    let mut weld: HashMap<[u32; 3], u32> = HashMap::with_capacity(soup.positions.len());
    let mut welded_pos: Vec<Vec3> = Vec::new();
    let mut welded_uv: Vec<Vec2> = Vec::new();
    let mut corner_ids: Vec<u32> = Vec::with_capacity(soup.face_indices.len());
    for &i in &soup.face_indices {
        let p = soup.positions[i as usize];
        let id = *weld.entry(weld_key(p)).or_insert_with(|| {
            welded_pos.push(p);
            welded_uv.push(soup.uvs.as_ref().map_or(Vec2::ZERO, |uv| uv[i as usize]));
            (welded_pos.len() - 1) as u32
        });
        corner_ids.push(id);
    }

    // 2. Fan-triangulate; remember which triangle sides are polygon sides (structural).
    let scale = bbox_diagonal(&welded_pos).max(f32::MIN_POSITIVE);
    let min_area = 1e-10 * scale * scale;
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(soup.face_indices.len());
    let mut tri_sides: Vec<[SpringKind; 3]> = Vec::with_capacity(tris.capacity());
    let mut seen: HashMap<[u32; 3], ()> = HashMap::new();
    let (mut degenerate, mut duplicate) = (0usize, 0usize);
    let mut start = 0usize;
    for &arity in &soup.face_arities {
        let face = &corner_ids[start..start + arity as usize];
        start += arity as usize;
        let n = face.len();
        for k in 1..n - 1 {
            let t = [face[0], face[k], face[k + 1]];
            let side = |boundary: bool| {
                if boundary {
                    SpringKind::Structural
                } else {
                    SpringKind::Shear
                }
            };
            // Sides: (t0,t1) is a polygon side iff k == 1, (t1,t2) always, (t2,t0) iff k+1 == n-1.
            let sides = [side(k == 1), side(true), side(k + 1 == n - 1)];
            let [a, b, c] = t.map(|i| welded_pos[i as usize]);
            if t[0] == t[1]
                || t[1] == t[2]
                || t[0] == t[2]
                || 0.5 * (b - a).cross(c - a).length() <= min_area
            {
                degenerate += 1;
                continue;
            }
            let mut key = t;
            key.sort_unstable();
            if seen.insert(key, ()).is_some() {
                duplicate += 1;
                continue;
            }
            tris.push(t);
            tri_sides.push(sides);
        }
    }
    if degenerate > 0 {
        warnings.push(format!(
            "dropped {degenerate} zero-area or collapsed triangle(s)"
        ));
    }
    if duplicate > 0 {
        warnings.push(format!("dropped {duplicate} duplicate triangle(s)"));
    }
    if tris.is_empty() {
        return Err(ObjError::Empty {
            path: source.to_path_buf(),
            detail: format!("{} face(s), none with positive area", soup.face_count()),
        });
    }

    // 3. Keep only particles that a kept triangle uses, in first-use order.
    let mut remap = vec![u32::MAX; welded_pos.len()];
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for t in &mut tris {
        for i in t.iter_mut() {
            if remap[*i as usize] == u32::MAX {
                remap[*i as usize] = positions.len() as u32;
                positions.push(welded_pos[*i as usize]);
                uvs.push(welded_uv[*i as usize]);
            }
            *i = remap[*i as usize];
        }
    }
    let unused = welded_pos.len() - positions.len();
    if unused > 0 {
        warnings.push(format!(
            "dropped {unused} vertex/vertices used only by dropped triangles"
        ));
    }
    if soup.uvs.is_none() {
        uvs = planar_uvs(&positions);
    }

    // 4. Unique edges and bend pairs: sort the 3·T half-edges by their vertex pair.
    let mut half: Vec<(u32, u32, SpringKind, u32)> = Vec::with_capacity(tris.len() * 3);
    for (t, sides) in tris.iter().zip(&tri_sides) {
        for s in 0..3 {
            let (a, b, opposite) = (t[s], t[(s + 1) % 3], t[(s + 2) % 3]);
            half.push((a.min(b), a.max(b), sides[s], opposite));
        }
    }
    half.sort_unstable();
    let mut edges = Vec::new();
    let mut edge_kinds = Vec::new();
    let mut bend_pairs = Vec::new();
    let mut non_manifold = 0usize;
    for group in half.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        edges.push([group[0].0, group[0].1]);
        // Sorting puts Structural first: an edge that is any polygon's side is structural.
        edge_kinds.push(group[0].2);
        match group {
            [_, _] if group[0].3 != group[1].3 => {
                let (p, q) = (group[0].3, group[1].3);
                bend_pairs.push([p.min(q), p.max(q)]);
            }
            [_] | [_, _] => {}
            _ => non_manifold += 1,
        }
    }
    if non_manifold > 0 {
        warnings.push(format!(
            "{non_manifold} edge(s) shared by more than two triangles get no bending"
        ));
    }

    Ok(MeshBuild {
        mesh: ClothMesh {
            positions,
            uvs,
            triangles: tris,
            edges,
            edge_kinds,
            bend_pairs,
        },
        warnings,
    })
}

fn bbox_diagonal(points: &[Vec3]) -> f32 {
    let (lo, hi) = bounds(points);
    (hi - lo).length()
}

/// Axis-aligned bounds `(min, max)` of a point set; `(0, 0)` when empty.
pub fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    if points.is_empty() {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    points.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
        (lo.min(p), hi.max(p))
    })
}

/// Index (0 = x, 1 = y, 2 = z) of the smallest extent of the box `lo..hi`: the normal
/// axis of a flat cloth. Ties go to the lower index.
pub fn thinnest_axis(lo: Vec3, hi: Vec3) -> usize {
    let ext = hi - lo;
    if ext.x <= ext.y && ext.x <= ext.z {
        0
    } else if ext.y <= ext.z {
        1
    } else {
        2
    }
}

impl ClothMesh {
    /// Number of mesh edges of the given kind.
    pub fn edge_count(&self, kind: SpringKind) -> usize {
        self.edge_kinds.iter().filter(|&&k| k == kind).count()
    }
}
