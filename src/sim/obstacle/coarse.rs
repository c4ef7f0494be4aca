//! What a coarse cloth can reach of an obstacle's gentle parts. A cloth edge whose two
//! particles each keep the thickness off the faces can still sink through the surface
//! between them where the surface falls away under it by more than that: a rail of narrow
//! faces under a cloth of 20 cm quads, or the low apex of a roof. Its first touch is at an
//! edge or a vertex of the surface, never inside a face (nor along an edge between two
//! faces in one plane); so an edge of the surface that the cloth can reach is kept off as
//! the creases are, and a vertex as the tips are.
//!
//! The bound. Take a point `x` of the surface's edge or vertex and the plane through it of
//! one of its faces. Where the surface within distance `d` of `x` falls below that plane by
//! at most `f(d)`, a particle at distance `dᵢ` and at least the thickness `h` off the
//! surface lies at least `h − f(dᵢ)` above the plane. A cloth edge through `x` has `x` at
//! weights `wᵢ` of its two particles, and a cloth triangle over a vertex at its barycentric
//! weights; either passes at least `h − Σ wᵢ f(dᵢ)` above `x`. The faces' slopes (their
//! turn from that plane) are gathered in rings of distance from `x`; integrated they give
//! `f(d) ≤ a·d + b·d²`, `a` the steepest slope near `x` and `b` how fast the slopes grow
//! farther out. With `Σ wᵢdᵢ` and `Σ wᵢdᵢ²` bounded by the cloth's own shape (an edge of
//! length `ℓ` through `x`: `ℓ/2` and `ℓ²/4`; a triangle: its circumradius and its square,
//! at most its longest edge and its square), the cloth reaches `x` only where
//! `a·Σ wᵢdᵢ + b·Σ wᵢdᵢ² ≥ h`.

use std::collections::{HashMap, HashSet};

use glam::Vec3;
use rayon::prelude::*;

use super::edges::CREASE_COS;
use super::geometry::welded;

/// A part of the surface counts as reachable where the bound leaves less than this share
/// of the thickness: room for the rounding, the rings' coarseness, and the particles'
/// own catch, which may leave one a hair inside the thickness.
const MARGIN: f32 = 0.75;

/// Rings of distance the slopes are gathered in, out to the cloth's longest edge.
const RINGS: usize = 8;

/// Two faces closer to one plane than this (the cosine between their normals) lie in one
/// plane as far as `f32` tells: no first touch is there.
pub(super) const FLAT_COS: f32 = 1.0 - 1e-6;

/// How far a cloth's edges and triangles span and the thickness it keeps off a surface:
/// what decides which of the surface's gentle edges and vertices it can reach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClothSpan {
    /// Its longest triangle edge, m, stretched as far as it may be.
    pub edge: f32,
    /// Its largest triangle's lever (the smaller of its circumradius and its longest
    /// edge), m, stretched likewise.
    pub lever: f32,
    /// The thickness kept off the surface, m.
    pub thickness: f32,
}

/// A surface's faces as the bound reads them: each one's unit normal and box, and its
/// neighbours across its edges where the two meet neither at a crease nor at a border.
/// The bound follows the surface from a point through those alone: beyond a crease (a
/// table's rim, a drum's cap) the crease itself keeps the cloth off.
pub(super) struct Faces<'a> {
    triangles: &'a [[u32; 3]],
    normals: &'a [Vec3],
    /// What a walk reads of each face, side by side.
    walked: Vec<Walked>,
    /// Each vertex's first at its place.
    same: Vec<u32>,
}

/// A face as the walks read it: its box, its unit normal, and its neighbours across its
/// three edges.
#[derive(Clone, Copy)]
struct Walked {
    lo: Vec3,
    hi: Vec3,
    normal: Vec3,
    across: [u32; 3],
}

/// No neighbour across an edge.
const NONE: u32 = u32::MAX;

/// Faces a piece of the work takes at once (each piece walks with scratch of its own).
const PIECE: usize = 2048;

/// The scratch of the bound's walks over a surface's faces: each face's last walk, the
/// walks so far, and the faces met in the current one, in order.
struct Walk {
    seen: Vec<u32>,
    walks: u32,
    met: Vec<u32>,
}

impl Walk {
    fn over(faces: &Faces<'_>) -> Self {
        Walk {
            seen: vec![0; faces.normals.len()],
            walks: 0,
            met: Vec::new(),
        }
    }
}

impl<'a> Faces<'a> {
    /// The faces `triangles` over `vertices` (vertices at one place are one), each with
    /// its unit normal in `normals` (zero for a degenerate one, which has no neighbours).
    pub(super) fn new(vertices: &[Vec3], triangles: &'a [[u32; 3]], normals: &'a [Vec3]) -> Self {
        let same = welded(vertices);
        let mut sides: HashMap<(u32, u32), Vec<(u32, u8)>> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            if normals[t] == Vec3::ZERO {
                continue;
            }
            let tri = tri.map(|i| same[i as usize]);
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let side = (t as u32, k as u8);
                sides.entry((a.min(b), a.max(b))).or_default().push(side);
            }
        }
        let mut across = vec![[NONE; 3]; triangles.len()];
        for faces in sides.values() {
            if let [(s, j), (t, k)] = faces[..]
                && normals[s as usize].dot(normals[t as usize]).abs() >= CREASE_COS
            {
                across[s as usize][j as usize] = t;
                across[t as usize][k as usize] = s;
            }
        }
        let walked = (triangles.iter().zip(normals).zip(across))
            .map(|((t, &normal), across)| {
                let [p, q, r] = t.map(|i| vertices[i as usize]);
                let (lo, hi) = (p.min(q).min(r), p.max(q).max(r));
                Walked {
                    lo,
                    hi,
                    normal,
                    across,
                }
            })
            .collect();
        Self {
            triangles,
            normals,
            walked,
            same,
        }
    }

    /// The cosine of the angle between the faces `s` and `t` (unsigned).
    fn turn(&self, [s, t]: [u32; 2]) -> f32 {
        self.normals[s as usize].dot(self.normals[t as usize]).abs()
    }

    /// The edges between two faces (by their two vertices, each the first at its place,
    /// the lesser first) that a cloth of `span` can reach (at `vertices`), taken face by
    /// face, in pieces shared among the threads.
    pub(super) fn reachable_edges(
        &self,
        span: &ClothSpan,
        vertices: &[Vec3],
    ) -> HashSet<(u32, u32)> {
        let count = self.triangles.len();
        let pieces: Vec<Vec<(u32, u32)>> = (0..count.div_ceil(PIECE))
            .into_par_iter()
            .map(|piece| {
                let mut walk = Walk::over(self);
                let mut reached = Vec::new();
                for s in piece * PIECE..count.min((piece + 1) * PIECE) {
                    for (k, &t) in self.walked[s].across.iter().enumerate() {
                        if t == NONE || (t as usize) < s {
                            continue;
                        }
                        let tri = self.triangles[s];
                        let [a, b] = [tri[k], tri[(k + 1) % 3]].map(|i| self.same[i as usize]);
                        let ends = [a, b].map(|i| vertices[i as usize]);
                        if span.reaches_edge(self, &mut walk, ends, [s as u32, t]) {
                            reached.push((a.min(b), a.max(b)));
                        }
                    }
                }
                reached
            })
            .collect();
        pieces.into_iter().flatten().collect()
    }

    /// The vertices (each the first at its place) whose faces turn from each other, by
    /// less than a crease, that a cloth of `span` can reach (at `vertices`), in pieces
    /// shared among the threads.
    pub(super) fn reachable_vertices(&self, span: &ClothSpan, vertices: &[Vec3]) -> HashSet<u32> {
        // Each vertex's faces, by vertex.
        let mut fans: Vec<(u32, u32)> = (self.triangles.iter().enumerate())
            .filter(|&(t, _)| self.normals[t] != Vec3::ZERO)
            .flat_map(|(t, tri)| tri.map(|i| (self.same[i as usize], t as u32)))
            .collect();
        fans.sort_unstable();
        let fans: Vec<&[(u32, u32)]> = fans.chunk_by(|a, b| a.0 == b.0).collect();
        let pieces: Vec<Vec<u32>> = (fans.par_chunks(PIECE))
            .map(|piece| {
                let mut walk = Walk::over(self);
                let mut reached = Vec::new();
                for fan in piece {
                    // The two faces that turn most from each other.
                    let mut most = (1.0f32, fan[0].1, fan[0].1);
                    for (k, &(_, s)) in fan.iter().enumerate() {
                        for &(_, t) in &fan[k + 1..] {
                            let cos = self.turn([s, t]);
                            if cos < most.0 {
                                most = (cos, s, t);
                            }
                        }
                    }
                    let (v, (cos, s, t)) = (fan[0].0, most);
                    let at = vertices[v as usize];
                    if cos >= CREASE_COS && span.reaches_vertex(self, &mut walk, at, [s, t], cos) {
                        reached.push(v);
                    }
                }
                reached
            })
            .collect();
        pieces.into_iter().flatten().collect()
    }
}

impl ClothSpan {
    /// The span of `triangles` over `rest`, each length stretched by `stretch` (1 for
    /// none), keeping `thickness`.
    pub fn of(rest: &[Vec3], triangles: &[[u32; 3]], stretch: f32, thickness: f32) -> Self {
        let (mut edge, mut lever) = (0.0f32, 0.0f32);
        for t in triangles {
            let [a, b, c] = t.map(|i| rest[i as usize]);
            let lengths = [a.distance(b), b.distance(c), c.distance(a)];
            let longest = lengths[0].max(lengths[1]).max(lengths[2]);
            let twice_area = (b - a).cross(c - a).length();
            let circumradius = if twice_area > 0.0 {
                lengths[0] * lengths[1] * lengths[2] / (2.0 * twice_area)
            } else {
                f32::INFINITY
            };
            edge = edge.max(longest);
            lever = lever.max(circumradius.min(longest));
        }
        let stretch = stretch.max(1.0);
        Self {
            edge: edge * stretch,
            lever: lever * stretch,
            thickness,
        }
    }

    /// Whether a cloth edge can reach the surface's edge from `a` to `b` between the faces
    /// `s` and `t`.
    fn reaches_edge(
        &self,
        faces: &Faces<'_>,
        walk: &mut Walk,
        [a, b]: [Vec3; 2],
        [s, t]: [u32; 2],
    ) -> bool {
        let half = 0.5 * self.edge;
        let flat = faces.turn([s, t]) >= FLAT_COS;
        let (need, box_) = (self.need(), (a.min(b), a.max(b)));
        !flat && self.dip((faces, walk), box_, [s, t], (half, half * half), need) >= need
    }

    /// Whether a cloth triangle can reach the surface's vertex at `v`, whose faces turn
    /// from each other by at most the angle of cosine `turn` (unsigned), `s` and `t` the
    /// two that turn most.
    fn reaches_vertex(
        &self,
        faces: &Faces<'_>,
        walk: &mut Walk,
        v: Vec3,
        [s, t]: [u32; 2],
        turn: f32,
    ) -> bool {
        let (lever, need) = (self.lever, self.need());
        let bound = (lever, lever * lever);
        turn < FLAT_COS && self.dip((faces, walk), (v, v), [s, t], bound, need) >= need
    }

    /// How far the bound lets a cloth come into a surface: the thickness less a margin.
    fn need(&self) -> f32 {
        MARGIN * self.thickness
    }

    /// How far at most (m) a cloth whose weighted distances from a point of the box
    /// `lo..hi` are at most `first` (`Σ wᵢdᵢ`) and `second` (`Σ wᵢdᵢ²`) comes below its
    /// particles' offset from the surface there: the surface within the cloth's longest
    /// edge, walked from the faces `s` and `t` (whose bisecting plane the slopes are
    /// measured from), falls away that far under it. Infinite where a face there stands
    /// at a right angle to that plane. As soon as the slopes nearest the box alone take it
    /// to `enough`, what they take it to.
    fn dip(
        &self,
        (faces, walk): (&Faces<'_>, &mut Walk),
        (lo, hi): (Vec3, Vec3),
        [s, t]: [u32; 2],
        (first, second): (f32, f32),
        enough: f32,
    ) -> f32 {
        let reach = self.edge;
        if !(reach > 0.0 && reach.is_finite()) {
            return 0.0;
        }
        let (n, m) = (faces.normals[s as usize], faces.normals[t as usize]);
        let reference = (n + m * n.dot(m).signum()).normalize_or(n);
        // The steepest slope in each ring (as the least cosine), from the faces met walking
        // out from `s` across gentle and flat edges (nearest first), as far as the reach.
        let mut least = [1.0f32; RINGS];
        let stop = if first > 0.0 {
            enough / first
        } else {
            f32::INFINITY
        };
        let stop_cos = 1.0 / (1.0 + stop * stop).sqrt();
        walk.walks += 1;
        let walked = walk.walks;
        walk.met.clear();
        walk.met.push(s);
        walk.seen[s as usize] = walked;
        let mut at = 0;
        while let Some(&t) = walk.met.get(at) {
            at += 1;
            let face = faces.walked[t as usize];
            let apart = (face.lo - hi).max(lo - face.hi).max(Vec3::ZERO).length();
            if apart > reach {
                continue;
            }
            let ring = ((apart / reach * RINGS as f32) as usize).min(RINGS - 1);
            let cos = face.normal.dot(reference).abs();
            least[ring] = least[ring].min(cos);
            if least[0] <= stop_cos {
                return slope(least[0]) * first;
            }
            for u in face.across {
                if u != NONE && walk.seen[u as usize] != walked {
                    walk.seen[u as usize] = walked;
                    walk.met.push(u);
                }
            }
        }
        // f(d) ≤ a·d + b·d²: the slope at distance s is at most the steepest within s,
        // which `a + 2b·s` bounds from each ring's inner radius on.
        let slopes = least.map(slope);
        let a = slopes[0];
        let mut steepest = a;
        let mut b = 0.0f32;
        for (k, &slope) in slopes.iter().enumerate().skip(1) {
            steepest = steepest.max(slope);
            let inner = reach * k as f32 / RINGS as f32;
            b = b.max((steepest - a) / (2.0 * inner));
        }
        a * first + b * second
    }
}

/// The slope of a face at the angle of cosine `cos` (unsigned) from a plane: infinite at
/// a right angle.
fn slope(cos: f32) -> f32 {
    if cos > 0.0 {
        (1.0 - cos * cos).max(0.0).sqrt() / cos
    } else {
        f32::INFINITY
    }
}

/// A closed prism of `sides` narrow faces round the x axis, `radius` from it and 2 m long,
/// with flat ends (a rail: its only vertices are at its ends), as vertices and triangles:
/// for tests.
#[cfg(test)]
pub(crate) fn prism(sides: u32, radius: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut vertices = Vec::new();
    for k in 0..sides {
        let a = std::f32::consts::TAU * k as f32 / sides as f32;
        let (y, z) = (radius * a.sin(), radius * a.cos());
        vertices.extend([Vec3::new(-1.0, y, z), Vec3::new(1.0, y, z)]);
    }
    vertices.extend([Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)]);
    let (left, right) = (2 * sides, 2 * sides + 1);
    let mut triangles = Vec::new();
    for k in 0..sides {
        let [a, b] = [2 * k, 2 * k + 1];
        let [c, d] = [2 * ((k + 1) % sides), 2 * ((k + 1) % sides) + 1];
        triangles.extend([[a, c, d], [a, d, b], [left, c, a], [right, b, d]]);
    }
    (vertices, triangles)
}

#[cfg(test)]
mod tests;
