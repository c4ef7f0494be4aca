//! Fan triangulation of welded polygons: which triangle sides are polygon sides, which are
//! diagonals, and the second diagonal of every quad.

use rustc_hash::FxHashSet;

use glam::Vec3;

use super::spring_kind::SpringKind;

/// Triangles of a polygon soup, with what each side of each triangle is.
#[derive(Default)]
pub struct Triangulation {
    pub triangles: Vec<[u32; 3]>,
    /// Kind of the sides `(t0,t1)`, `(t1,t2)`, `(t2,t0)` of each triangle: structural for a
    /// polygon side, shear for a fan diagonal.
    pub sides: Vec<[SpringKind; 3]>,
    /// The diagonal of each quad that the fan did not draw (`[min, max]`). Together with
    /// the fan diagonal it makes shear stiffness the same along both diagonals.
    pub cross_diagonals: Vec<[u32; 2]>,
    /// Triangles dropped for zero area or repeated corners.
    pub degenerate: usize,
    /// Triangles dropped because the same three particles already form one.
    pub duplicate: usize,
}

/// Fan-triangulates faces given as particle ids (`corners`, split by `arities`). A
/// triangle with area at most `min_area` (m²) or a repeated corner is dropped.
pub fn triangulate(
    positions: &[Vec3],
    corners: &[u32],
    arities: &[u32],
    min_area: f32,
) -> Triangulation {
    let mut out = Triangulation::default();
    let mut seen: FxHashSet<[u32; 3]> =
        FxHashSet::with_capacity_and_hasher(corners.len(), Default::default());
    let mut start = 0usize;
    for &arity in arities {
        let Some(face) = corners.get(start..start + arity as usize) else {
            break; // arities that overrun the corners (never from a valid parse)
        };
        start += arity as usize;
        let mut kept = 0;
        // A "face" of fewer than three corners (a point or a polyline) has no triangle.
        for k in 1..face.len().saturating_sub(1) {
            let t = [face[0], face[k], face[k + 1]];
            if is_degenerate(positions, t, min_area) {
                out.degenerate += 1;
                continue;
            }
            let mut key = t;
            key.sort_unstable();
            if !seen.insert(key) {
                out.duplicate += 1;
                continue;
            }
            out.triangles.push(t);
            out.sides.push(fan_sides(k, face.len()));
            kept += 1;
        }
        if face.len() == 4 && kept == 2 {
            let (a, b) = (face[1], face[3]);
            out.cross_diagonals.push([a.min(b), a.max(b)]);
        }
    }
    out
}

/// Sides of fan triangle `k` (corners 0, k, k+1) of an `n`-gon: `(0,k)` is a polygon side
/// only for the first triangle, `(k,k+1)` always is, `(k+1,0)` only for the last.
fn fan_sides(k: usize, n: usize) -> [SpringKind; 3] {
    let side = |polygon_side: bool| {
        if polygon_side {
            SpringKind::Structural
        } else {
            SpringKind::Shear
        }
    };
    [side(k == 1), side(true), side(k + 1 == n - 1)]
}

fn is_degenerate(positions: &[Vec3], t: [u32; 3], min_area: f32) -> bool {
    if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
        return true;
    }
    let [a, b, c] = t.map(|i| positions[i as usize]);
    0.5 * (b - a).cross(c - a).length() <= min_area
}
