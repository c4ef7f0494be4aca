//! The exact intersection check: which triangles of the cloth meet each other, and which
//! meet an obstacle, decided by the signs of orientation tests computed exactly (Shewchuk's
//! adaptive predicates, the `robust` crate; an f32 coordinate is exact in f64). Plain f64
//! is not enough: a flat cloth's triangles are exactly coplanar, and rounding gives their
//! volumes signs that make neighbours cross. Plain f64 only tells apart, first, two
//! triangles that lie apart along the line between their middles by more than rounding
//! could close. It judges a state; it moves nothing.
//!
//! Two triangles of the cloth that share an edge always touch along it and are not
//! counted; two that share one vertex are tested on the edge each has opposite it; the
//! rest are counted when they share any point.

use glam::{DVec3, Vec3};

use super::effects::Effect;
use super::obstacle::TriangleTree;
use super::self_contacts::point_triangle_distance;

/// How many triangle pairs meet, for the cloth against itself and against each obstacle.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Intersections {
    /// Pairs of the cloth's own triangles that meet.
    #[serde(rename = "self")]
    pub self_pairs: usize,
    /// One count per solid, in the scene's order: for a mesh obstacle the (cloth triangle,
    /// obstacle triangle) pairs that meet; for a sphere or a plane the cloth triangles that
    /// reach inside it.
    pub obstacles: Vec<usize>,
}

impl Intersections {
    /// Every count added up.
    pub fn total(&self) -> usize {
        self.self_pairs + self.obstacles.iter().sum::<usize>()
    }

    /// The larger of each count of `self` and `other` (obstacles matched by place).
    pub fn max(&self, other: &Intersections) -> Intersections {
        let n = self.obstacles.len().max(other.obstacles.len());
        let at = |v: &[usize], k: usize| v.get(k).copied().unwrap_or(0);
        Intersections {
            self_pairs: self.self_pairs.max(other.self_pairs),
            obstacles: (0..n)
                .map(|k| at(&self.obstacles, k).max(at(&other.obstacles, k)))
                .collect(),
        }
    }
}

/// The exact sign of the volume of (a, b, c, d): positive when d lies on the side of the
/// plane (a, b, c) that its normal (b − a) × (c − a) points to.
fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let at = |p: DVec3| robust::Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    };
    // Shewchuk's sign is the other way round.
    -robust::orient3d(at(a), at(b), at(c), at(d))
}

/// The exact sign of the area of (a, b, c) in the plane of the two axes `u`, `v`.
fn orient2(a: DVec3, b: DVec3, c: DVec3, [u, v]: [usize; 2]) -> f64 {
    let at = |p: DVec3| robust::Coord { x: p[u], y: p[v] };
    robust::orient2d(at(a), at(b), at(c))
}

/// Whether segments (a, b) and (c, d), coplanar, share a point (seen along the axes `uv`).
fn segments_meet_2d(a: DVec3, b: DVec3, c: DVec3, d: DVec3, uv: [usize; 2]) -> bool {
    let (o1, o2) = (orient2(a, b, c, uv), orient2(a, b, d, uv));
    let (o3, o4) = (orient2(c, d, a, uv), orient2(c, d, b, uv));
    let within = |p: DVec3, q: DVec3, r: DVec3| {
        (0..2).all(|k| r[uv[k]] >= p[uv[k]].min(q[uv[k]]) && r[uv[k]] <= p[uv[k]].max(q[uv[k]]))
    };
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return true;
    }
    (o1 == 0.0 && within(a, b, c))
        || (o2 == 0.0 && within(a, b, d))
        || (o3 == 0.0 && within(c, d, a))
        || (o4 == 0.0 && within(c, d, b))
}

/// Whether `p` lies in triangle `t` (edges included), seen along the axes `uv`.
fn inside_2d(p: DVec3, [a, b, c]: [DVec3; 3], uv: [usize; 2]) -> bool {
    let s = [
        orient2(a, b, p, uv),
        orient2(b, c, p, uv),
        orient2(c, a, p, uv),
    ];
    s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0)
}

/// The two axes of the plane a normal `n` is most nearly along.
fn axes_across(n: DVec3) -> [usize; 2] {
    let a = n.abs();
    if a.x >= a.y && a.x >= a.z {
        [1, 2]
    } else if a.y >= a.z {
        [2, 0]
    } else {
        [0, 1]
    }
}

/// Whether segment (a, b) and triangle `t`, in one plane of normal `n`, share a point.
fn segment_meets_coplanar(a: DVec3, b: DVec3, t: [DVec3; 3], n: DVec3) -> bool {
    let uv = axes_across(n);
    inside_2d(a, t, uv)
        || inside_2d(b, t, uv)
        || (0..3).any(|k| segments_meet_2d(a, b, t[k], t[(k + 1) % 3], uv))
}

/// Whether segment (a, b) shares a point with triangle `t` (not degenerate).
pub fn segment_meets_triangle(a: DVec3, b: DVec3, t: [DVec3; 3]) -> bool {
    let [p, q, r] = t;
    let (sa, sb) = (orient(p, q, r, a), orient(p, q, r, b));
    if sa * sb > 0.0 {
        return false;
    }
    if sa == 0.0 && sb == 0.0 {
        return segment_meets_coplanar(a, b, t, (q - p).cross(r - p));
    }
    // The segment crosses the plane; it meets the triangle where it passes inside all
    // three edges (the signs of the three volumes agree, zeros allowed).
    let s = [orient(a, b, p, q), orient(a, b, q, r), orient(a, b, r, p)];
    s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0)
}

fn degenerate([a, b, c]: [DVec3; 3]) -> bool {
    (b - a).cross(c - a) == DVec3::ZERO
}

/// Whether the points `a` and the points `b` lie apart along the line between their
/// middles by more than any rounding of the projections could close (their hulls then
/// share no point): told in plain f64, so that the exact tests are asked only of what it
/// cannot tell. Neighbours on a flat cloth, exactly coplanar, lie apart so, and would
/// otherwise take the predicates' slowest, exact paths.
fn apart_along_middles(a: &[DVec3], b: &[DVec3]) -> bool {
    let middle = |x: &[DVec3]| x.iter().sum::<DVec3>() / x.len() as f64;
    let axis = middle(b) - middle(a);
    let (upper, lower) = (
        a.iter()
            .map(|p| axis.dot(*p))
            .fold(f64::NEG_INFINITY, f64::max),
        b.iter().map(|p| axis.dot(*p)).fold(f64::INFINITY, f64::min),
    );
    // Each projection is a sum of three products no larger than `size` times the axis'
    // largest component, each rounded; the axis, from sums of the points, is rounded too.
    let size = (a.iter().chain(b)).fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let rounding = 1e-12 * size * size;
    lower - upper > rounding
}

/// Whether triangles `s` and `t` share a point.
pub fn triangles_meet(s: [DVec3; 3], t: [DVec3; 3]) -> bool {
    !apart_along_middles(&s, &t) && triangles_meet_exactly(s, t)
}

/// [`triangles_meet`], every case by the exact tests.
fn triangles_meet_exactly(s: [DVec3; 3], t: [DVec3; 3]) -> bool {
    let edges = |x: [DVec3; 3]| [(x[0], x[1]), (x[1], x[2]), (x[2], x[0])];
    match (degenerate(s), degenerate(t)) {
        (true, true) => return false,
        (true, false) => {
            return edges(s)
                .iter()
                .any(|&(a, b)| segment_meets_triangle(a, b, t));
        }
        (false, true) => {
            return edges(t)
                .iter()
                .any(|&(a, b)| segment_meets_triangle(a, b, s));
        }
        (false, false) => {}
    }
    let side =
        |plane: [DVec3; 3], x: [DVec3; 3]| x.map(|v| orient(plane[0], plane[1], plane[2], v));
    let apart = |d: [f64; 3]| d.iter().all(|&x| x > 0.0) || d.iter().all(|&x| x < 0.0);
    let (ds, dt) = (side(t, s), side(s, t));
    if apart(ds) || apart(dt) {
        return false;
    }
    if ds.iter().all(|&x| x == 0.0) {
        let n = (s[1] - s[0]).cross(s[2] - s[0]);
        return edges(s)
            .iter()
            .any(|&(a, b)| segment_meets_coplanar(a, b, t, n))
            || inside_2d(t[0], s, axes_across(n));
    }
    // Not coplanar: where they meet, an edge of one passes through the other.
    edges(s)
        .iter()
        .any(|&(a, b)| segment_meets_triangle(a, b, t))
        || edges(t)
            .iter()
            .any(|&(a, b)| segment_meets_triangle(a, b, s))
}

fn wide(p: Vec3) -> DVec3 {
    p.as_dvec3()
}

/// Whether two triangles of one mesh (corner numbers `s`, `t`, at `pos`) intersect: not at
/// all when they share an edge; on the edge opposite a shared vertex; else anywhere.
pub fn mesh_triangles_intersect(s: [u32; 3], t: [u32; 3], pos: &[Vec3]) -> bool {
    let corners = |x: [u32; 3]| x.map(|i| wide(pos[i as usize]));
    let mut shared = s.iter().filter(|i| t.contains(i));
    match (shared.next(), shared.next()) {
        (None, _) => triangles_meet(corners(s), corners(t)),
        (Some(&v), None) => {
            let opposite = |x: [u32; 3]| {
                let k = x.iter().position(|&i| i == v).unwrap_or(0);
                (
                    wide(pos[x[(k + 1) % 3] as usize]),
                    wide(pos[x[(k + 2) % 3] as usize]),
                )
            };
            let ((a, b), (c, d)) = (opposite(s), opposite(t));
            let meets = |a: DVec3, b: DVec3, t: [DVec3; 3]| {
                !degenerate(t)
                    && !apart_along_middles(&[a, b], &t)
                    && segment_meets_triangle(a, b, t)
            };
            meets(a, b, corners(t)) || meets(c, d, corners(s))
        }
        _ => false,
    }
}

fn corners_of(triangles: &[[u32; 3]], pos: &[Vec3]) -> Vec<[Vec3; 3]> {
    (triangles.iter())
        .map(|t| t.map(|i| pos[i as usize]))
        .collect()
}

/// Pairs of the mesh's own triangles (`triangles` over `pos`) that intersect.
pub fn self_intersections(triangles: &[[u32; 3]], pos: &[Vec3]) -> usize {
    let corners = corners_of(triangles, pos);
    let tree = TriangleTree::new(&corners);
    let mut count = 0;
    for (s, c) in corners.iter().enumerate() {
        let [a, b, d] = *c;
        tree.overlapping(a.min(b).min(d), a.max(b).max(d), |t| {
            let t = t as usize;
            if t > s && mesh_triangles_intersect(triangles[s], triangles[t], pos) {
                count += 1;
            }
        });
    }
    count
}

/// Pairs of a cloth triangle and an `other` triangle (corners) that meet.
pub fn intersections_between(triangles: &[[u32; 3]], pos: &[Vec3], other: &[[Vec3; 3]]) -> usize {
    let tree = TriangleTree::new(other);
    let mut count = 0;
    for t in triangles {
        let [a, b, c] = t.map(|i| pos[i as usize]);
        let cloth = [a, b, c].map(wide);
        tree.overlapping(a.min(b).min(c), a.max(b).max(c), |o| {
            if triangles_meet(cloth, other[o as usize].map(wide)) {
                count += 1;
            }
        });
    }
    count
}

/// The cloth (`triangles` at `pos`) against every solid among `effects` at simulated time
/// `time`, and against itself.
pub fn intersections(
    effects: &[Effect],
    time: f64,
    triangles: &[[u32; 3]],
    pos: &[Vec3],
) -> Intersections {
    let mut obstacles = Vec::new();
    for effect in effects {
        match effect {
            Effect::Obstacle(o) => {
                let Some(placed) = o.placed() else {
                    obstacles.push(0);
                    continue;
                };
                let world = placed.world_vertices(time);
                let other = corners_of(placed.surface.triangles(), &world);
                obstacles.push(intersections_between(triangles, pos, &other));
            }
            Effect::Sphere(s) => {
                let centre = wide(s.center);
                let inside = (triangles.iter())
                    .filter(|t| {
                        point_triangle_distance(centre, t.map(|i| wide(pos[i as usize])))
                            < f64::from(s.radius)
                    })
                    .count();
                obstacles.push(inside);
            }
            Effect::Plane(p) => {
                let (point, normal) = (wide(p.point), wide(p.unit_normal()));
                let below = (triangles.iter())
                    .filter(|t| {
                        t.iter()
                            .any(|&i| (wide(pos[i as usize]) - point).dot(normal) < 0.0)
                    })
                    .count();
                obstacles.push(below);
            }
            _ => {}
        }
    }
    Intersections {
        self_pairs: self_intersections(triangles, pos),
        obstacles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filter along the middles never tells apart what the exact tests find meeting:
    /// on triangles drawn from the points of a small grid (exactly coplanar at z = 0.3, or
    /// tilted, where rounding leaves them a hair off one plane), sharing points, touching
    /// along edges, or a hair apart, the check with it and without it agree, and so do a
    /// segment's and a triangle's; it tells apart nearly half of the pairs that do not
    /// meet (many of the others overlap in their boxes across the grid, or are
    /// degenerate).
    #[test]
    fn the_filter_along_the_middles_tells_apart_only_what_does_not_meet() {
        let mut rnd = crate::test_rng::uniform(23);
        let (mut told, mut met, mut segments_told) = (0, 0, 0);
        for trial in 0..20_000 {
            let tilted = trial % 2 == 1;
            let mut point = |spread: f32| {
                let (i, j) = ((rnd() * spread) as i32, (rnd() * spread) as i32);
                let (x, y) = (0.013 * i as f32 - 0.02, 0.017 * j as f32 + 0.5);
                let z = if tilted {
                    0.3 + 0.37 * x - 0.21 * y
                } else {
                    0.3
                };
                let hair = if rnd() < 0.2 {
                    1e-7 * (rnd() - 0.5)
                } else {
                    0.0
                };
                wide(Vec3::new(x + hair, y, z))
            };
            let spread = if trial % 3 == 0 { 3.0 } else { 8.0 };
            let s = [point(spread), point(spread), point(spread)];
            let t = [point(spread), point(spread), point(spread)];
            let exact = triangles_meet_exactly(s, t);
            assert_eq!(triangles_meet(s, t), exact, "{s:?} {t:?}");
            told += usize::from(apart_along_middles(&s, &t));
            met += usize::from(exact);
            if !degenerate(t) && apart_along_middles(&s[..2], &t) {
                segments_told += 1;
                assert!(!segment_meets_triangle(s[0], s[1], t), "{s:?} {t:?}");
            }
        }
        assert!(told > 3000 && met > 8000, "{told} told apart, {met} meet");
        assert!(segments_told > 3000, "{segments_told}");
    }
}
