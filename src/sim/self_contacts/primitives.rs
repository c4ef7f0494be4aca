//! The two kinds of contact between a cloth and itself — a vertex against a triangle, an
//! edge against an edge — their closest points, and the push that keeps one a thickness
//! from the other.

use glam::{DVec3, Vec3};

use crate::cloth::{ClothModel, ClothState};
use crate::sim::obstacle::{closest_weights, segments_closest};

/// A pair that may come into contact: vertex 0 against triangle (1, 2, 3), or edge (0, 1)
/// against edge (2, 3); the four particles are distinct. Sixteen bytes: which kind rides in
/// the top bit of the first particle's number (a cloth has fewer than 2³¹ particles).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pair([u32; 4]);

/// The bit that marks an edge–edge pair.
const EDGES: u32 = 1 << 31;

/// A [`Pair`] as the search stores it, in eight bytes: vertex `0` against triangle number
/// `1`, or the edges numbered `0` and `1` (an edge's number is three times its triangle's
/// plus its side in it), the kind in the top bit of the first. Half a [`Pair`]'s size:
/// where a cloth lands fast its pairs are counted in millions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct StoredPair([u32; 2]);

impl StoredPair {
    /// Vertex `v` against triangle number `t`.
    pub fn vertex_triangle(v: u32, t: u32) -> StoredPair {
        StoredPair([v, t])
    }

    /// The edges numbered `e` and `f`.
    pub fn edge_edge(e: u32, f: u32) -> StoredPair {
        StoredPair([e | EDGES, f])
    }

    /// The pair, given the cloth's `triangles` and each triangle's three `edges`.
    pub fn expand(self, triangles: &[[u32; 3]], edges: &[[[u32; 2]; 3]]) -> Pair {
        let [a, b] = self.0;
        if a & EDGES == 0 {
            Pair::vertex_triangle(a, triangles[b as usize])
        } else {
            let edge = |n: u32| edges[n as usize / 3][n as usize % 3];
            Pair::edge_edge(edge(a & !EDGES), edge(b))
        }
    }

    /// The same pair with an edge–edge pair's edges in order of their numbers (which comes
    /// first depends on which triangle a search started from).
    #[cfg(test)]
    pub fn canonical(self) -> StoredPair {
        let [a, b] = self.0;
        if a & EDGES == 0 {
            self
        } else {
            let (e, f) = (a & !EDGES, b);
            StoredPair::edge_edge(e.min(f), e.max(f))
        }
    }

    /// The two triangles whose search found it: the owner of the vertex (`vertex_owner`:
    /// each vertex's owning triangle) and the triangle, or the edges' triangles.
    pub fn triangles(self, vertex_owner: &[u32]) -> [u32; 2] {
        let [a, b] = self.0;
        if a & EDGES == 0 {
            [vertex_owner[a as usize], b]
        } else {
            [(a & !EDGES) / 3, b / 3]
        }
    }
}

impl Pair {
    /// Vertex `v` against triangle `t`.
    pub fn vertex_triangle(v: u32, t: [u32; 3]) -> Pair {
        Pair([v, t[0], t[1], t[2]])
    }

    /// Edge `e` against edge `f`.
    pub fn edge_edge(e: [u32; 2], f: [u32; 2]) -> Pair {
        Pair([e[0] | EDGES, e[1], f[0], f[1]])
    }

    /// Whether it is an edge–edge pair.
    pub fn edges(&self) -> bool {
        self.0[0] & EDGES != 0
    }

    /// Its four particles.
    pub fn ids(&self) -> [usize; 4] {
        [
            (self.0[0] & !EDGES) as usize,
            self.0[1] as usize,
            self.0[2] as usize,
            self.0[3] as usize,
        ]
    }

    /// The weights that make the pair's two closest points from its four particles: the
    /// first point is Σ `w[i]` x_i over the first side, the second over the other (both
    /// sides' weights sum to one).
    pub fn weights(&self, x: [Vec3; 4]) -> [f32; 4] {
        if self.edges() {
            let [p0, p1, q0, q1] = x.map(|v| v.as_dvec3());
            let (s, t) = segments_closest(p0, p1, q0, q1);
            [1.0 - s as f32, s as f32, 1.0 - t as f32, t as f32]
        } else {
            let b = closest_weights(x[0], [x[1], x[2], x[3]]);
            [1.0, b[0], b[1], b[2]]
        }
    }

    /// How many of the four particles belong to the first side.
    pub fn first_side(&self) -> usize {
        if self.edges() { 2 } else { 1 }
    }
}

/// The least of `least` and the pair's distance with its particles at `x`, measured (in
/// f64) only where the boxes of its two sides lie nearer than `least`: a running least
/// over many pairs, most of which their boxes pass by.
pub(super) fn nearer(pair: &Pair, x: &[Vec3], least: f64) -> f64 {
    let ids = pair.ids();
    let [a, b] = side_boxes(pair, ids.map(|i| x[i]));
    if boxes_apart_by(a, b, least) {
        least
    } else {
        least.min(distance(pair, ids.map(|i| x[i].as_dvec3())))
    }
}

/// The boxes of the pair's two sides with its four particles at `x`.
fn side_boxes(pair: &Pair, x: [Vec3; 4]) -> [(Vec3, Vec3); 2] {
    let k = pair.first_side();
    let side = |r: std::ops::Range<usize>| {
        r.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), i| {
            (lo.min(x[i]), hi.max(x[i]))
        })
    };
    [side(0..k), side(k..4)]
}

/// Whether boxes `a` and `b` lie at least `least` apart (less a rounding's worth of it):
/// then nothing in one is nearer than that to anything in the other.
pub(super) fn boxes_apart_by(
    (alo, ahi): (Vec3, Vec3),
    (blo, bhi): (Vec3, Vec3),
    least: f64,
) -> bool {
    let gap = f64::from((blo - ahi).max(alo - bhi).max(Vec3::ZERO).length());
    gap * (1.0 - 1e-6) >= least
}

/// The share of a distance by which a pair told apart by its planes or lines must clear
/// it where an exact test in f32 would decide ([`separation`]).
const BOUND_ROUNDING: f64 = 1e-3;

/// Edges whose directions' cross product is shorter than this share of their lengths'
/// product are too near parallel for their lines' distance to be measured.
const NEAR_PARALLEL: f64 = 1e-6;

/// Whether the pair's two sides with its particles at `x` lie at least `d` apart by a
/// lower bound on their distance at a fraction of its cost ([`distance`]), in f64: the
/// vertex's distance from the triangle's plane, or the distance between the edges' lines
/// (false where the triangle is degenerate or the edges parallel). Where cloths lie
/// stacked over a curve (`layers` over its sphere), their sides' boxes overlap but their
/// planes lie apart: most of the continuous check's pairs there are settled so, and about
/// a quarter of the pushes' that reach the closest points.
#[inline(always)]
pub fn apart_by_planes(pair: &Pair, x: [DVec3; 4], d: f64) -> bool {
    let (n, along, least) = if pair.edges() {
        let (u, v) = (x[1] - x[0], x[3] - x[2]);
        let n = u.cross(v);
        let least = NEAR_PARALLEL * NEAR_PARALLEL * u.length_squared() * v.length_squared();
        (n, x[2] - x[0], least)
    } else {
        let n = (x[2] - x[1]).cross(x[3] - x[1]);
        (n, x[0] - x[1], 0.0)
    };
    let n2 = n.length_squared();
    let h = along.dot(n);
    n2 > least && d >= 0.0 && h * h >= d * d * n2
}

/// The distance between the pair's two sides with its particles at `x`, in f64.
pub fn distance(pair: &Pair, x: [DVec3; 4]) -> f64 {
    if pair.edges() {
        let (s, t) = segments_closest(x[0], x[1], x[2], x[3]);
        (x[0] + s * (x[1] - x[0])).distance(x[2] + t * (x[3] - x[2]))
    } else {
        point_triangle_distance(x[0], [x[1], x[2], x[3]])
    }
}

/// The distance from `p` to triangle (a, b, c), in f64.
pub fn point_triangle_distance(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let n = (b - a).cross(c - a);
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| (v - u).cross(p - u).dot(n) >= 0.0);
    if inside && n != DVec3::ZERO {
        return (p - a).dot(n).abs() / n.length();
    }
    let to_segment = |u: DVec3, v: DVec3| {
        let d = v - u;
        let s = if d == DVec3::ZERO {
            0.0
        } else {
            ((p - u).dot(d) / d.length_squared()).clamp(0.0, 1.0)
        };
        p.distance(u + s * d)
    };
    to_segment(a, b).min(to_segment(b, c)).min(to_segment(c, a))
}

/// Where the pair's sides are closer than `d` with its particles at `x`, the weights of
/// their closest points ([`Pair::weights`]) and the offset between them (first side less
/// the other); where they are not, how far apart they are at least (the gap between their
/// boxes along an axis, or their closest points' distance, as rounded).
fn separation(pair: &Pair, x: [Vec3; 4], d: f32) -> Result<([f32; 4], Vec3), f32> {
    let k = pair.first_side();
    // Sides whose boxes are `d` apart along an axis are not closer.
    let [(alo, ahi), (blo, bhi)] = side_boxes(pair, x);
    let apart = (blo - ahi).max(alo - bhi).max_element();
    if apart >= d {
        return Err(apart);
    }
    // Nor are sides whose planes or lines lie that far apart (kept short of it by more
    // than the rounding of the exact test below, which measures in f32).
    let clear = f64::from(d) * (1.0 + BOUND_ROUNDING);
    if apart_by_planes(pair, x.map(|v| v.as_dvec3()), clear) {
        return Err(d);
    }
    let w = pair.weights(x);
    let sign = |i: usize| if i < k { 1.0 } else { -1.0 };
    let gap: Vec3 = (0..4).map(|i| sign(i) * w[i] * x[i]).sum();
    let length = gap.length();
    if length < d {
        Ok((w, gap))
    } else {
        Err(length)
    }
}

/// Keeps the pair's sides `thickness` apart, on the side they were on at the substep's
/// start (`start`): each particle moves by its share of the push (its weight times its
/// inverse mass); the approaching relative velocity is removed and Coulomb `friction`
/// applied to the sliding part. Particles `held` (resting on a solid) move only where
/// nothing else in the pair can. Returns whether it pushed, or (`Err`) how far apart its
/// sides were at least where they were not closer than the thickness: measured where
/// they are closer than `within` (at least the thickness), and where not, at least that.
pub fn push_apart<P: Particles + ?Sized>(
    pair: &Pair,
    [thickness, friction, within]: [f32; 3],
    model: &ClothModel,
    start: &[Vec3],
    state: &mut P,
    held: &[bool],
) -> Result<bool, f32> {
    let ids = pair.ids();
    let k = pair.first_side();
    let (w, gap) = separation(pair, ids.map(|i| state.pos(i)), within.max(thickness))?;
    let dist = gap.length();
    if dist >= thickness {
        return Err(dist);
    }
    // Signed weights: the first side counts positively, the other negatively.
    let sign = |i: usize| if i < k { 1.0 } else { -1.0 };
    // Which side: the sides' offset at the start, at the same weights.
    let before: Vec3 = (0..4).map(|i| sign(i) * w[i] * start[ids[i]]).sum();
    let direction = if before.length_squared() > 0.0 && gap.dot(before) > 0.0 && dist > 1e-9 {
        gap / dist
    } else if let Some(n) = before.try_normalize() {
        n
    } else if let Some(n) = gap.try_normalize() {
        n
    } else {
        return Ok(false);
    };
    let depth = thickness - gap.dot(direction);
    if depth <= 0.0 {
        return Ok(false);
    }
    let held = |i: usize| held.get(i).copied().unwrap_or(false);
    let mut inv = ids.map(|i| if held(i) { 0.0 } else { model.inv_mass[i] });
    let mut weight: f32 = (0..4).map(|i| w[i] * w[i] * inv[i]).sum();
    if weight <= 0.0 {
        inv = ids.map(|i| model.inv_mass[i]);
        weight = (0..4).map(|i| w[i] * w[i] * inv[i]).sum();
    }
    if weight <= 0.0 {
        return Ok(false);
    }
    // No particle moves farther than the depth: a pair whose only free particle barely
    // weighs in its side (a small weight) is pushed partly, not flung.
    let most = (0..4).map(|i| w[i] * inv[i]).fold(0.0f32, f32::max);
    let share = (weight / most).min(1.0);
    let lambda = share * depth / weight;
    for i in 0..4 {
        state.move_by(ids[i], (sign(i) * w[i] * inv[i] * lambda) * direction);
    }
    let relative: Vec3 = (0..4).map(|i| sign(i) * w[i] * state.vel(ids[i])).sum();
    let approach = relative.dot(direction);
    if approach < 0.0 {
        let sliding = relative - approach * direction;
        let speed = sliding.length();
        let friction = if speed > 0.0 {
            (friction * -approach / speed).min(1.0)
        } else {
            0.0
        };
        let impulse = share * (-approach * direction - friction * sliding) / weight;
        for i in 0..4 {
            state.speed_up(ids[i], (sign(i) * w[i] * inv[i]) * impulse);
        }
    }
    Ok(true)
}

/// The particles a push reads and moves: a whole cloth's state, or (on the pushes' team)
/// the part of it one group of pairs reaches.
pub trait Particles {
    fn pos(&self, i: usize) -> Vec3;
    fn vel(&self, i: usize) -> Vec3;
    /// Moves particle `i` by `by`.
    fn move_by(&mut self, i: usize, by: Vec3);
    /// Adds `by` to particle `i`'s velocity.
    fn speed_up(&mut self, i: usize, by: Vec3);
}

impl Particles for ClothState {
    #[inline(always)]
    fn pos(&self, i: usize) -> Vec3 {
        self.pos[i]
    }
    #[inline(always)]
    fn vel(&self, i: usize) -> Vec3 {
        self.vel[i]
    }
    #[inline(always)]
    fn move_by(&mut self, i: usize, by: Vec3) {
        self.pos[i] += by;
    }
    #[inline(always)]
    fn speed_up(&mut self, i: usize, by: Vec3) {
        self.vel[i] += by;
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::test_rng::{jitter, uniform};

    /// A running least takes in a pair nearer than the least so far, to the rounding its
    /// box test allows for, and keeps the least where the pair is not nearer: on random
    /// vertex–triangle and edge–edge pairs with a least so far up to twice their distance
    /// (so that many lie apart by their sides' boxes and are passed by), each step gives
    /// the least of the pair's distance and the least before.
    #[test]
    fn a_running_least_takes_in_every_pair_nearer_than_it() {
        let mut rnd = crate::test_rng::uniform(12);
        let x: Vec<Vec3> = (0..400)
            .map(|_| Vec3::new(rnd(), rnd(), rnd()) * 0.1)
            .collect();
        let (mut passed, mut taken) = (0, 0);
        for n in 0..20_000 {
            let [a, b, c, d] = std::array::from_fn(|_| (rnd() * 400.0) as u32 % 400);
            if [b, c, d].contains(&a) || b == c || b == d || c == d {
                continue;
            }
            let pair = if n % 2 == 0 {
                Pair::vertex_triangle(a, [b, c, d])
            } else {
                Pair::edge_edge([a, b], [c, d])
            };
            let exact = distance(&pair, pair.ids().map(|i| x[i].as_dvec3()));
            let before = exact * f64::from(2.0 * rnd());
            let expected = before.min(exact);
            let least = nearer(&pair, &x, before);
            assert!(
                (least - expected).abs() <= 1e-6 * expected,
                "{least} against {expected}"
            );
            let [s, t] = side_boxes(&pair, pair.ids().map(|i| x[i]));
            passed += usize::from(boxes_apart_by(s, t, before));
            taken += usize::from(exact < before);
        }
        assert!(
            passed > 1000 && taken > 1000,
            "{passed} passed by, {taken} taken in"
        );
    }

    /// A pair told apart by its planes or lines is at least that far apart: over random
    /// pairs of both kinds within a centimetre (a thickness's scale), each `d` the bound
    /// settles lies within the pair's distance, and the bound settles a good share of
    /// them (a vertex above a tilted triangle, crossing edges one above the other).
    #[test]
    fn pairs_told_apart_by_their_planes_are_that_far_apart() {
        let (mut at, mut unit) = (jitter(7), uniform(11));
        let mut settled = [0usize; 2];
        for k in 0..20_000 {
            let pair = if k % 2 == 0 {
                Pair::vertex_triangle(0, [1, 2, 3])
            } else {
                Pair::edge_edge([0, 1], [2, 3])
            };
            let x: [DVec3; 4] = std::array::from_fn(|_| at(0.01).as_dvec3());
            let d = 0.01 * f64::from(unit());
            if apart_by_planes(&pair, x, d) {
                let exact = distance(&pair, x);
                assert!(exact >= d * (1.0 - 1e-12), "{pair:?} {x:?}: {exact} < {d}");
                settled[k % 2] += 1;
            }
        }
        // Each kind: at least a tenth of the draws settled.
        assert!(settled.iter().all(|&s| s > 1_000), "{settled:?}");
        // Parallel edges have no line between them to measure: never settled.
        let parallel = [DVec3::ZERO, DVec3::X, DVec3::Z, DVec3::Z + DVec3::X];
        assert!(!apart_by_planes(
            &Pair::edge_edge([0, 1], [2, 3]),
            parallel,
            0.5
        ));
    }
}
