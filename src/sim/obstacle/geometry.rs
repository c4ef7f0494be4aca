//! Points, segments and triangles: the closest point of a triangle to a point, and where a
//! segment crosses a triangle.

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use rayon::slice::ParallelSliceMut;

/// Each vertex's number as the first vertex at its place (the same bits in every
/// coordinate, −0 as +0): a surface written with its faces apart is one surface.
pub fn welded(vertices: &[Vec3]) -> Vec<u32> {
    let place = |v: &Vec3| v.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() });
    let mut first_at: HashMap<[u32; 3], u32> = HashMap::with_capacity(vertices.len());
    (vertices.iter().enumerate())
        .map(|(i, v)| *first_at.entry(place(v)).or_insert(i as u32))
        .collect()
}

/// A margin for the rounding of distances measured among points no farther from the
/// origin than `p` is along any axis: ten times it (f32 rounds a distance to about a
/// millionth of the coordinates), far below any thickness. What a remembered distance is
/// trusted to, less this.
pub fn rounding_near(p: Vec3) -> f32 {
    1e-5 * (1.0 + p.abs().max_element())
}

/// A remembered distance `d` (m) after the surface moved by up to `by` metres: that much
/// less, with a ten-thousandth of `by` more for the rounding of the move, rounded down.
pub fn less_by_move(d: f32, by: f32) -> f32 {
    (d - by * (1.0 + 1e-4)).next_down()
}

/// The point of triangle `abc` closest to `p` (its inside, an edge or a corner).
pub fn closest_on_triangle(p: Vec3, t: [Vec3; 3]) -> Vec3 {
    let w = closest_weights(p, t);
    w[0] * t[0] + w[1] * t[1] + w[2] * t[2]
}

/// The barycentric weights on `a`, `b`, `c` of the point of triangle `abc` closest to `p`.
pub fn closest_weights(p: Vec3, [a, b, c]: [Vec3; 3]) -> [f32; 3] {
    // Ericson, Real-Time Collision Detection, 5.1.5: the Voronoi regions of the corners,
    // then of the edges, then the inside.
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [1.0 - v - w, v, w]
}

/// Where along segments `p0`–`p1` and `q0`–`q1` (0 at the first end, 1 at the second) their
/// nearest points lie, in f64. Ericson 5.1.9, with a point for a segment and parallel
/// segments (any nearest pair then).
pub fn segments_closest(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> (f64, f64) {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    if a <= f64::EPSILON && e <= f64::EPSILON {
        return (0.0, 0.0);
    }
    if a <= f64::EPSILON {
        return (0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(r);
    if e <= f64::EPSILON {
        return ((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(d2);
    let denom = a * e - b * b;
    let mut s = if denom > 0.0 {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (s, t)
}

/// The barycentric weights of `p` (a point of the triangle's plane) on `a`, `b`, `c`
/// (a degenerate triangle: all on `a`).
pub fn barycentric(p: Vec3, [a, b, c]: [Vec3; 3]) -> [f32; 3] {
    let (e0, e1, e2) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (e2.dot(e0), e2.dot(e1));
    let denom = d00 * d11 - d01 * d01;
    if denom <= f32::EPSILON * d00 * d11 || denom <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let v = (d11 * d20 - d01 * d21) / denom;
    let w = (d00 * d21 - d01 * d20) / denom;
    [1.0 - v - w, v, w]
}

/// Where, as a fraction of the way from `from` to `to`, the segment first crosses triangle
/// `abc` (either side; touching counts), if it does.
pub fn segment_crosses(from: Vec3, to: Vec3, [a, b, c]: [Vec3; 3]) -> Option<f32> {
    let d = to - from;
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    // Parallel to the plane (or a degenerate triangle): no single crossing point.
    if det.abs() <= f32::EPSILON * e1.length_squared().max(e2.length_squared()) * d.length() {
        return None;
    }
    let inv = 1.0 / det;
    let s = from - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (0.0..=1.0).contains(&t).then_some(t)
}

/// The squared distance from `p` to the box `lo..hi` (0 inside).
pub fn box_distance_squared(p: Vec3, lo: Vec3, hi: Vec3) -> f32 {
    (lo - p).max(p - hi).max(Vec3::ZERO).length_squared()
}

/// Whether the segment from `from` to `to` meets the box `lo..hi`.
pub fn segment_meets_box(from: Vec3, to: Vec3, lo: Vec3, hi: Vec3) -> bool {
    let d = to - from;
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for k in 0..3 {
        if d[k].abs() < 1e-12 {
            if from[k] < lo[k] || from[k] > hi[k] {
                return false;
            }
            continue;
        }
        let inv = 1.0 / d[k];
        let (a, b) = ((lo[k] - from[k]) * inv, (hi[k] - from[k]) * inv);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// Each side of each of `triangles` that `keep` keeps (by triangle number), as its two
/// ends by `same` (each vertex's first at its place, the lesser first) and `3 × triangle +
/// side`, in order: the sides along one edge together, by their triangles.
pub(super) fn sides_by_edge(
    triangles: &[[u32; 3]],
    same: &[u32],
    keep: impl Fn(usize) -> bool,
) -> Vec<([u32; 2], u32)> {
    let mut sides: Vec<([u32; 2], u32)> = (triangles.iter().enumerate())
        .filter(|&(t, _)| keep(t))
        .flat_map(|(t, tri)| {
            let tri = tri.map(|i| same[i as usize]);
            [0, 1, 2].map(|k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                ([a.min(b), a.max(b)], 3 * t as u32 + k as u32)
            })
        })
        .collect();
    sides.par_sort_unstable();
    sides
}

/// Each of `triangles`' unit normal over `vertices` (zero for a degenerate one).
pub(super) fn face_normals(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    (triangles.iter())
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: [Vec3; 3] = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];

    /// Each region of the triangle: above its inside, beside each edge, past each corner;
    /// checked against a brute-force search over the triangle.
    #[test]
    fn the_closest_point_is_the_closest_of_all() {
        let mut rnd = crate::test_rng::uniform(9);
        for _ in 0..2000 {
            let p = Vec3::new(rnd() * 3.0 - 1.0, rnd() * 3.0 - 1.0, rnd() * 2.0 - 1.0);
            let q = closest_on_triangle(p, T);
            let mut best = f32::INFINITY;
            let n = 200;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let s = T[0]
                        + (T[1] - T[0]) * (i as f32 / n as f32)
                        + (T[2] - T[0]) * (j as f32 / n as f32);
                    best = best.min(p.distance(s));
                }
            }
            assert!(p.distance(q) <= best + 1e-6, "{p}: {q}");
            assert!(
                p.distance(q) >= best - 0.01,
                "{p}: {q} nearer than the grid allows"
            );
        }
    }

    #[test]
    fn a_segment_crosses_where_it_meets_the_plane_inside_the_triangle() {
        let down = |x: f32, y: f32| (Vec3::new(x, y, 1.0), Vec3::new(x, y, -3.0));
        let (a, b) = down(0.25, 0.25);
        assert_eq!(segment_crosses(a, b, T), Some(0.25));
        assert_eq!(segment_crosses(b, a, T), Some(0.75), "from below too");
        let (a, b) = down(0.75, 0.75);
        assert_eq!(segment_crosses(a, b, T), None, "beside the hypotenuse");
        let (a, _) = down(0.25, 0.25);
        assert_eq!(
            segment_crosses(a, Vec3::new(0.25, 0.25, 0.5), T),
            None,
            "short of it"
        );
        // Along the plane: no single point.
        assert_eq!(
            segment_crosses(Vec3::new(-1.0, 0.2, 0.0), Vec3::new(2.0, 0.2, 0.0), T),
            None
        );
    }

    #[test]
    fn segments_and_points_meet_boxes_where_they_should() {
        let (lo, hi) = (Vec3::ZERO, Vec3::ONE);
        assert!(segment_meets_box(
            Vec3::splat(-1.0),
            Vec3::splat(2.0),
            lo,
            hi
        ));
        assert!(segment_meets_box(
            Vec3::splat(0.5),
            Vec3::splat(0.6),
            lo,
            hi
        ));
        assert!(!segment_meets_box(
            Vec3::new(2.0, 0.5, 0.5),
            Vec3::new(3.0, 0.5, 0.5),
            lo,
            hi
        ));
        assert!(!segment_meets_box(
            Vec3::new(-1.0, 2.0, 0.5),
            Vec3::new(2.0, 1.5, 0.5),
            lo,
            hi
        ));
        assert_eq!(box_distance_squared(Vec3::splat(0.5), lo, hi), 0.0);
        assert_eq!(box_distance_squared(Vec3::new(3.0, 0.5, 2.0), lo, hi), 5.0);
    }
}
