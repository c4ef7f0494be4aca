//! A second certificate for the patches of a cloth that lies flat at rest: how far each
//! triangle's deformation gradient strays from the patch's map, rather than how far each
//! particle strays from where the map puts it.
//!
//! Where a patch's rest shape is one convex region of a plane, two points `P` and `Q` of
//! it are joined at rest by the straight segment between them, inside the patch. The
//! cloth's placement is linear on each triangle, its gradient there `Fₜ`; less the
//! patch's linear map `M` (fitted as for the first certificate), what is left is linear on
//! each triangle too, with gradient `Fₜ − M`, so along the segment it changes by at most
//! `ε = maxₜ ‖Fₜ − M‖` per metre of rest. Hence `|x(P) − x(Q)| ≥ (σ − ε)·|P − Q|`, `σ` the
//! least `M` stretches any direction, and two sides of a pair, at least the rest gap
//! apart at rest, keep at least `(σ − ε)·gap` apart. Along the motion each particle moves
//! in a straight line, so each `Fₜ − M` runs linearly from its value at the start to its
//! value at the end (at most the larger of the two) and `σ` keeps the Weyl bound of the
//! first certificate. A patch bent evenly (draped over a sphere, curled over an edge) keeps
//! far from any linear map of its rest shape yet turns its triangles little from one to
//! the next: the first certificate fails there and this one holds.
//!
//! Nothing of this holds where the rest shape is not one flat convex region: two stacked
//! cloths, or a piece lying in a hole of another, may move alike (every `Fₜ = M`) and
//! still meet. So a cloth whose rest positions do not lie in one plane gets no such
//! certificate, and a patch whose triangles at rest do not make one convex region (an edge
//! that only one of its triangles has, with an end of another such edge beyond it)
//! neither. What the rounding may leave of either (a particle off the plane, or beyond an
//! edge, by up to [`ROUNDING`] of the cloth's extent) is taken four times over from the
//! rest gap the certificate counts on.

use glam::{Mat3, Vec2, Vec3, Vec3A};

use super::super::certify::frame;
use super::super::rings::Rings;
use super::super::search::NONE;

/// Rounding allowed for, as a part of the rest shape's extent (one plus its largest
/// coordinate, m): how far off its plane a flat cloth's particle may lie, and beyond an
/// edge of a convex patch.
const ROUNDING: f32 = 1e-5;

/// More than one triangle across an edge ([`NONE`]: none).
const MANY: u32 = u32::MAX - 1;

/// A cloth that lies flat at rest.
#[derive(Clone, Debug)]
pub(super) struct Flat {
    /// Turns rest offsets into the plane's frame (its first two axes in the plane).
    pub(super) back: Mat3,
    /// Each triangle's rest edges in the plane, inverted: row-major `[a, b, c, d]` of the
    /// inverse of the matrix whose columns are its second and third corners' offsets from
    /// its first (NaN where it has no area: a patch holding it is never so certified).
    slopes: Vec<[f32; 4]>,
    /// How far a particle may lie off the plane, or beyond an edge of a convex patch, m.
    slack: f32,
}

/// What deciding which patches are convex reads, at setup only: each particle's place at
/// rest in the plane, each triangle's neighbour across each of its edges (edge `k` from
/// corner `k` to the next: the other triangle that has it, [`NONE`] for none, [`MANY`]
/// for more than one), the rounding allowed for, and room for a patch's edges and their
/// ends, kept from one patch to the next.
pub(super) struct Outline {
    places: Vec<Vec2>,
    across: Vec<[u32; 3]>,
    slack: f32,
    edges: Vec<[u32; 3]>,
    ends: Vec<Vec2>,
}

impl Flat {
    /// The plane of a cloth of `triangles` whose `rest` positions lie in one (up to the
    /// rounding), the plane through `a`, `b` and `c` (three of them far apart), with the
    /// cloth's outline in it, from each particle's triangles (`rings`); `None` where they
    /// do not lie in it.
    pub(super) fn of(
        triangles: &[[u32; 3]],
        rest: &[Vec3],
        [a, b, c]: [Vec3; 3],
        rings: &Rings,
    ) -> Option<(Flat, Outline)> {
        let back = frame(a, b, c).transpose();
        let extent = (rest.iter()).fold(0.0f32, |m, p| m.max(p.abs().max_element()));
        let slack = ROUNDING * (1.0 + extent);
        let off = (rest.iter()).fold(0.0f32, |m, &p| m.max((back * (p - a)).z.abs()));
        // Three particles in a line turn no frame: the identity stands in, and the check
        // of every particle against its plane then decides.
        if off.is_nan() || off > slack || triangles.is_empty() {
            return None;
        }
        let places: Vec<Vec2> = rest.iter().map(|&p| (back * p).truncate()).collect();
        let slopes = (triangles.iter())
            .map(|t| {
                let [p, q, r] = t.map(|j| places[j as usize]);
                let (e1, e2) = (q - p, r - p);
                let det = e1.perp_dot(e2);
                if det == 0.0 {
                    return [f32::NAN; 4];
                }
                [e2.y / det, -e2.x / det, -e1.y / det, e1.x / det]
            })
            .collect();
        let across = (triangles.iter().enumerate())
            .map(|(t, c)| {
                std::array::from_fn(|k| {
                    let (a, b) = (c[k], c[(k + 1) % 3]);
                    let mut others = (rings.triangles_of(a as usize).iter())
                        .filter(|&&u| u as usize != t && triangles[u as usize].contains(&b));
                    match (others.next(), others.next()) {
                        (None, _) => NONE,
                        (Some(&u), None) => u,
                        _ => MANY,
                    }
                })
            })
            .collect();
        let outline = Outline {
            places,
            across,
            slack,
            edges: Vec::new(),
            ends: Vec::new(),
        };
        let flat = Flat {
            back,
            slopes,
            slack,
        };
        Some((flat, outline))
    }

    /// The rest gap less what the rounding of the plane and of the patches' edges could
    /// take from it, m (what the certificate may count on).
    pub(super) fn gap(&self, gap: f32) -> f32 {
        gap - 4.0 * self.slack
    }

    /// Whether every triangle of `tris` (of `triangles`) has its deformation gradient, in
    /// the plane's frame, within `room` (Frobenius norm, which bounds the stretch) of the
    /// map `[p, q]` of its end of the motion: `maps[0]` at `from`, `maps[1]` at `to`.
    pub(super) fn turns_within(
        &self,
        tris: &[u32],
        triangles: &[[u32; 3]],
        [from, to]: [&[Vec3A]; 2],
        maps: [[Vec3A; 2]; 2],
        room: f32,
    ) -> bool {
        let limit = room * room;
        let at = |x: &[Vec3A], j: u32| x[j as usize];
        tris.iter().all(|&t| {
            let [a, b, c] = triangles[t as usize];
            let s = self.slopes[t as usize];
            let strays = |x: &[Vec3A], [p, q]: [Vec3A; 2]| {
                let (e1, e2) = (at(x, b) - at(x, a), at(x, c) - at(x, a));
                let (u, v) = (e1 * s[0] + e2 * s[2], e1 * s[1] + e2 * s[3]);
                (u - p).length_squared() + (v - q).length_squared()
            };
            strays(from, maps[0]) <= limit && strays(to, maps[1]) <= limit
        })
    }
}

impl Outline {
    /// Whether triangles `tris` (of `triangles`) make one convex region at rest: every edge
    /// of one of them that no other of them has (`holds`: whether a triangle is one of
    /// them) keeps every end of those edges on its triangle's side, to the rounding (the
    /// region lies within the hull of its edges' ends). An edge of more than two triangles
    /// is no edge of a flat region: none is convex.
    pub(super) fn convex(
        &mut self,
        tris: &[u32],
        triangles: &[[u32; 3]],
        holds: impl Fn(u32) -> bool,
    ) -> bool {
        if tris.is_empty() {
            return false;
        }
        // The region's edges, each with the corner across it, and their ends (each twice
        // or more: checked again rather than sorted out).
        let (edges, ends, places) = (&mut self.edges, &mut self.ends, &self.places);
        let at = |j: u32| places[j as usize];
        edges.clear();
        ends.clear();
        for &t in tris {
            let c = triangles[t as usize];
            for k in 0..3 {
                match self.across[t as usize][k] {
                    MANY => return false,
                    next if next != NONE && holds(next) => {}
                    _ => {
                        edges.push([c[k], c[(k + 1) % 3], c[(k + 2) % 3]]);
                        ends.extend([at(c[k]), at(c[(k + 1) % 3])]);
                    }
                }
            }
        }
        edges.iter().all(|&[a, b, c]| {
            let (a, b) = (at(a), at(b));
            let along = b - a;
            let inside = along.perp_dot(at(c) - a);
            let length = along.length();
            if inside == 0.0 || length == 0.0 {
                return false;
            }
            let (side, beyond) = (inside.signum(), -self.slack * length);
            ends.iter().all(|&p| side * along.perp_dot(p - a) >= beyond)
        })
    }
}
