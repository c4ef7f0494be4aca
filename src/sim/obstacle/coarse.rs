//! What a coarse cloth can reach of an obstacle's gentle parts. A cloth edge whose two
//! particles each keep the thickness off the faces can still sink through the surface
//! between them where the surface falls away under it by more than that: a rail of narrow
//! faces under a cloth of 20 cm quads, or the low apex of a roof. Its first touch is at an
//! edge or a vertex of the surface, never inside a face (nor along an edge between two
//! faces in one plane); so an edge of the surface that the cloth can reach is kept off as
//! the creases are, and a vertex as the tips are.
//!
//! The bound. Take a point `x` of the surface's edge or vertex and the plane through it
//! that bisects two of its faces (the edge's two; the vertex's two that turn most from each
//! other). Where the surface within distance `d` of `x` falls below that plane by
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

use std::f32::consts::FRAC_PI_2;

use glam::Vec3;
use rayon::prelude::*;

use self::walks::{Faces, FacesAt, NONE, Walk, Walker};
use super::edges::CREASE_COS;

mod walks;

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

/// Faces (or vertices) a piece of the work takes at once.
const PIECE: usize = 2048;

/// Which group a vertex walks in: its piece, its cell, and (where it walks alone) itself.
type GroupKey = (u32, [i64; 3], u32);

/// Vertices whose walks are taken together at most ([`Faces::walk_together`]): a lane
/// each.
const TOGETHER: usize = crate::sim::kernels::LANES;

/// The side of the cells vertices are grouped in for their walks, in rings' widths.
const CELL: f32 = 4.0;

/// The gentle edges (their two vertices, each the first at its place, the lesser first)
/// and vertices (each the first at its place) of a surface that a cloth reaches, each in
/// order ([`super::Surface::reached_over`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Reached {
    pub edges: Vec<[u32; 2]>,
    pub vertices: Vec<u32>,
}

/// What the bound's walks over a surface measured for a cloth's reach (its longest edge
/// and its triangles' lever), whatever thickness the cloth keeps: how far a cloth
/// triangle over each gentle vertex, and a cloth edge across each gentle edge, can come
/// into the surface, the most in any of its places (a sequence's frames). A thickness then
/// only draws the line (`Dips::reached`), so a cloth keeping another thickness (a slider
/// dragged) is answered without walking again.
///
/// Each vertex's walk serves the edges round it (a face is at most an edge's length nearer
/// the edge than its end, and turns from the edge's faces at most as far again as the
/// end's reference does from them): a bound from above. An edge that bound leaves within
/// the line, or longer than the reach, or with an end its walk did not measure, takes a
/// walk of its own in each place, the first time a line asks for it; its answer is kept
/// too. (An edge reached in some place is reached there by its own walk, which its ends'
/// bound there holds: the most of each over the places keeps the verdict.)
pub struct Dips {
    /// The span measured for (its thickness aside).
    edge: f32,
    lever: f32,
    /// Each vertex's first at its place.
    same: Vec<u32>,
    /// Each gentle vertex (the first at its place; not at a crease, its faces not in one
    /// plane, in some place) and how far a cloth triangle over it comes in, m, in order.
    vertices: Vec<(u32, f32)>,
    /// By their ends, in order.
    edges: Vec<EdgeDip>,
}

/// An edge between two faces neither at a crease nor in one plane in some place (its ends
/// the first at their places, the lesser first; its faces), the bound its ends' walks give
/// (infinite where they give none), and its own walk's, once taken.
struct EdgeDip {
    ends: [u32; 2],
    faces: [u32; 2],
    by_ends: f32,
    own: Option<f32>,
}

impl std::fmt::Debug for Dips {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Dips")
            .field("edge", &self.edge)
            .field("lever", &self.lever)
            .field("vertices", &self.vertices.len())
            .field("edges", &self.edges.len())
            .finish_non_exhaustive()
    }
}

impl Dips {
    /// The walks over `triangles` in each of `places` (each as many vertices: a surface,
    /// then a sequence's other frames) for a cloth of `span` (its thickness aside); `same`
    /// gives each vertex the first at its place (by the first place). Each place's walks
    /// in pieces shared among the threads.
    pub(super) fn measure<'p>(
        places: impl IntoIterator<Item = &'p [Vec3]>,
        triangles: &[[u32; 3]],
        same: Vec<u32>,
        span: &ClothSpan,
    ) -> Self {
        let (mut vertices, mut edges) = (Vec::new(), Vec::new());
        for place in places {
            let read = FacesAt::of(place, triangles, &same);
            let faces = read.faces(triangles, &same);
            let around = faces.vertex_walks(place, span);
            vertices.extend((around.iter().enumerate()).filter_map(|(v, a)| {
                let around = a.as_ref()?;
                Some((v as u32, around.dip))
            }));
            edges.extend(faces.edge_bounds(place, &around, span));
        }
        // The most of each over the places.
        vertices.sort_unstable_by_key(|&(v, _)| v);
        vertices.dedup_by(|next, kept| {
            let same_vertex = next.0 == kept.0;
            if same_vertex {
                kept.1 = kept.1.max(next.1);
            }
            same_vertex
        });
        edges.sort_unstable_by_key(|e| e.ends);
        edges.dedup_by(|next, kept| {
            let same_edge = next.ends == kept.ends;
            if same_edge {
                kept.by_ends = kept.by_ends.max(next.by_ends);
            }
            same_edge
        });
        Self {
            edge: span.edge,
            lever: span.lever,
            same,
            vertices,
            edges,
        }
    }

    /// Whether these walks were taken for a cloth of `span`'s reach (of any thickness).
    pub(super) fn measures(&self, span: &ClothSpan) -> bool {
        (self.edge, self.lever) == (span.edge, span.lever)
    }

    /// How many edges have taken a walk of their own so far.
    #[cfg(test)]
    fn own_walks(&self) -> usize {
        self.edges.iter().filter(|e| e.own.is_some()).count()
    }

    /// The edges (by their two vertices, each the first at its place, the lesser first)
    /// and the vertices (each the first at its place) that a cloth of `span` reaches: where
    /// it comes into the surface by what `span` needs of the thickness or more, in some
    /// place. `places` and `triangles` are those measured; the edges that need a walk of
    /// their own for this line and had none take it now, in each place where they lie
    /// between two faces neither at a crease nor in one plane, shared among the threads.
    pub(super) fn reached<'p>(
        &mut self,
        places: impl IntoIterator<Item = &'p [Vec3]>,
        triangles: &[[u32; 3]],
        span: &ClothSpan,
    ) -> (Vec<[u32; 2]>, Vec<u32>) {
        let need = span.need();
        let asked: Vec<usize> = (self.edges.iter().enumerate())
            .filter(|(_, e)| e.by_ends >= need && e.own.is_none())
            .map(|(k, _)| k)
            .collect();
        if !asked.is_empty() {
            let measuring = ClothSpan {
                edge: self.edge,
                lever: self.lever,
                ..*span
            };
            let mut most = vec![f32::NEG_INFINITY; asked.len()];
            for place in places {
                let read = FacesAt::of(place, triangles, &self.same);
                let faces = read.faces(triangles, &self.same);
                let edges = &self.edges;
                (most.par_chunks_mut(PIECE).zip(asked.par_chunks(PIECE))).for_each_init(
                    || Walk::over(&faces),
                    |walk, (most, asked)| {
                        for (most, &k) in most.iter_mut().zip(asked) {
                            let e = &edges[k];
                            if (CREASE_COS..FLAT_COS).contains(&faces.turn(e.faces)) {
                                let edge = (e.ends, e.faces);
                                let own =
                                    measuring.edge_dip((&faces, walk), place, edge, [None; 2]);
                                *most = most.max(own);
                            }
                        }
                    },
                );
            }
            for (&k, most) in asked.iter().zip(most) {
                self.edges[k].own = Some(most);
            }
        }
        let edges = (self.edges.iter())
            .filter(|e| e.by_ends >= need && e.own.is_some_and(|own| own >= need))
            .map(|e| e.ends);
        let vertices = (self.vertices.iter()).filter(|&&(_, dip)| dip >= need);
        (edges.collect(), vertices.map(|&(v, _)| v).collect())
    }
}

impl Faces<'_> {
    /// Each vertex's walk (by the vertex, the first at its place; `None` for a vertex not
    /// walked: [`ClothSpan::walker`]) over these faces at `vertices`, taken in groups
    /// ([`Faces::groups`]: one walk over the faces a group reaches, each vertex gathering
    /// what its own would) shared among the threads.
    fn vertex_walks(&self, vertices: &[Vec3], span: &ClothSpan) -> Vec<Option<Around>> {
        let fans = self.fans();
        let fans: Vec<&[(u32, u32)]> = fans.chunk_by(|a, b| a.0 == b.0).collect();
        let walkers = (fans.par_iter()).filter_map(|fan| span.walker(self, vertices, fan));
        let (walkers, groups) = self.groups(walkers.collect(), CELL * span.width());
        // Each thread's scratch serves the pieces it takes.
        let width = span.width();
        let found: Vec<Vec<(u32, Around)>> = (groups.par_chunks(PIECE / TOGETHER))
            .map_init(
                || (Walk::over(self), Vec::new()),
                |(walk, least), piece| {
                    let mut found = Vec::new();
                    for group in piece {
                        let group = &walkers[group.clone()];
                        least.resize(group.len(), [1.0f32; 2 * RINGS]);
                        self.walk_together(walk, group, width, &mut least[..group.len()]);
                        let each = group.iter().zip(least.iter());
                        found.extend(
                            each.map(|(w, least)| (w.vertex, span.around_of(w, &least[..w.rings]))),
                        );
                    }
                    found
                },
            )
            .collect();
        let mut around = vec![None; vertices.len()];
        for (v, found) in found.into_iter().flatten() {
            around[v as usize] = Some(found);
        }
        around
    }

    /// `walkers` in groups that walk together: those of one piece of the surface
    /// ([`Faces::pieces`]: no walk leaves its starts' piece) whose places lie in one cube
    /// of a grid of `side`, up to [`TOGETHER`] a group; a vertex whose faces lie on
    /// several pieces walks alone. Returns the walkers in groups' order and the groups.
    fn groups<'f>(
        &self,
        walkers: Vec<Walker<'f>>,
        side: f32,
    ) -> (Vec<Walker<'f>>, Vec<std::ops::Range<usize>>) {
        let piece = self.pieces();
        let mut keyed: Vec<(GroupKey, Walker<'f>)> = (walkers.into_iter())
            .map(|w| {
                let first = piece[w.fan[0].1 as usize];
                let key = if w.fan.iter().all(|&(_, f)| piece[f as usize] == first) {
                    let cell = (w.at / side).floor().to_array().map(|c| c as i64);
                    (first, cell, 0)
                } else {
                    (NONE, [0; 3], w.vertex)
                };
                (key, w)
            })
            .collect();
        keyed.sort_unstable_by_key(|(key, _)| *key);
        let (keys, walkers): (Vec<_>, Vec<_>) = keyed.into_iter().unzip();
        let mut groups = Vec::new();
        let mut at = 0;
        for same in keys.chunk_by(|a, b| a == b) {
            let end = at + same.len();
            groups.extend(
                (at..end)
                    .step_by(TOGETHER)
                    .map(|s| s..(s + TOGETHER).min(end)),
            );
            at = end;
        }
        (walkers, groups)
    }

    /// Each edge between two faces neither at a crease nor in one plane here, with the
    /// bound its ends' walks `around` give, in pieces shared among the threads.
    fn edge_bounds(
        &self,
        vertices: &[Vec3],
        around: &[Option<Around>],
        span: &ClothSpan,
    ) -> Vec<EdgeDip> {
        let count = self.triangles.len();
        let pieces: Vec<Vec<EdgeDip>> = (0..count.div_ceil(PIECE))
            .into_par_iter()
            .map_init(
                || Walk::over(self),
                |walk, piece| {
                    let mut edges = Vec::new();
                    for s in piece * PIECE..count.min((piece + 1) * PIECE) {
                        for (k, &t) in self.walked[s].across.iter().enumerate() {
                            let sides = [s as u32, t];
                            if t == NONE || (t as usize) < s || self.turn(sides) >= FLAT_COS {
                                continue;
                            }
                            let tri = self.triangles[s];
                            let ends = [tri[k], tri[(k + 1) % 3]].map(|i| self.same[i as usize]);
                            let walks = ends.map(|v| around[v as usize].as_ref());
                            let by_ends = match walks {
                                [Some(_), Some(_)] => {
                                    span.edge_dip((self, walk), vertices, (ends, sides), walks)
                                }
                                _ => f32::INFINITY,
                            };
                            let [a, b] = ends;
                            edges.push(EdgeDip {
                                ends: [a.min(b), a.max(b)],
                                faces: sides,
                                by_ends,
                                own: None,
                            });
                        }
                    }
                    edges
                },
            )
            .collect();
        pieces.into_iter().flatten().collect()
    }
}

/// What one vertex's walk measured: the steepest turn (radians) from its reference of the
/// faces within each ring and every ring nearer, out to the reach and as far again as its
/// longest edge, and that reference; and how far a cloth triangle over the vertex comes
/// into the surface (m).
#[derive(Clone, Debug, PartialEq)]
struct Around {
    steepest: [f32; 2 * RINGS],
    rings: usize,
    reference: Vec3,
    dip: f32,
}

/// The bisecting plane's normal of two faces' normals (unsigned).
fn bisector(n: Vec3, m: Vec3) -> Vec3 {
    (n + m * n.dot(m).signum()).normalize_or(n)
}

/// How far at most (m) a cloth whose weighted distances from a point are at most `first`
/// (`Σ wᵢdᵢ`) and `second` (`Σ wᵢdᵢ²`) comes below its particles' offset from the surface
/// there, where the steepest slope of the faces within each ring of `width` and every ring
/// nearer is `slopes`: `f(d) ≤ a·d + b·d²`, the slope at distance s being at most the
/// steepest within s, which `a + 2b·s` bounds from each ring's inner radius on.
fn dip_of(slopes: [f32; RINGS], width: f32, (first, second): (f32, f32)) -> f32 {
    let a = slopes[0];
    let mut b = 0.0f32;
    for (k, &slope) in slopes.iter().enumerate().skip(1) {
        b = b.max((slope - a) / (2.0 * width * k as f32));
    }
    a * first + b * second
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
            if !lengths.iter().all(|l| l.is_finite()) {
                // A triangle gone non-finite spans nothing measurable.
                continue;
            }
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

    /// The width of the rings the slopes are gathered in: the reach (the cloth's longest
    /// edge) over [`RINGS`].
    fn width(&self) -> f32 {
        self.edge / RINGS as f32
    }

    /// How far the bound lets a cloth come into a surface: the thickness less a margin.
    fn need(&self) -> f32 {
        MARGIN * self.thickness
    }

    /// How far at most (m) a cloth edge comes into the surface at its edge between the
    /// vertices `ends` (at `vertices`) and the faces `[s, t]`: from its ends' walks where
    /// both measured them and it is no longer than the reach, else by a walk of its own.
    fn edge_dip(
        &self,
        (faces, walk): (&Faces<'_>, &mut Walk),
        vertices: &[Vec3],
        (ends, [s, t]): ([u32; 2], [u32; 2]),
        walks: [Option<&Around>; 2],
    ) -> f32 {
        let (half, width) = (0.5 * self.edge, self.width());
        if !(width > 0.0 && width.is_finite()) {
            return 0.0;
        }
        let bound = (half, half * half);
        let [a, b] = ends.map(|v| vertices[v as usize]);
        let reference = bisector(faces.normals[s as usize], faces.normals[t as usize]);
        let length = a.distance(b);
        if let [Some(one), Some(two)] = walks
            && length <= self.edge
        {
            // A face in the edge's ring `i` lies in its end's rings `i + shift` or nearer.
            let shift = (length / width).ceil() as usize;
            let mut slopes = [f32::INFINITY; RINGS];
            for end in [one, two] {
                let off = end.reference.dot(reference).abs().min(1.0).acos();
                for (i, slope) in slopes.iter_mut().enumerate() {
                    let turn = end.steepest[(i + shift).min(end.rings - 1)] + off;
                    let by_end = if turn < FRAC_PI_2 {
                        turn.tan()
                    } else {
                        f32::INFINITY
                    };
                    *slope = slope.min(by_end);
                }
            }
            return dip_of(slopes, width, bound);
        }
        let mut least = [1.0f32; RINGS];
        let box_ = (a.min(b), a.max(b));
        faces.walk_rings(walk, [s], (box_, reference), (width, &mut least));
        dip_of(steepest(least).map(f32::tan), width, bound)
    }

    /// The walk the vertex of `fan` takes (its faces, by the vertex, first at its place,
    /// at `vertices`): from its place, measured from the plane that bisects its two faces
    /// that turn most from each other, out to the reach and as far again as its longest
    /// edge; `None` for a vertex at a crease (a tip already) or whose faces lie in one
    /// plane.
    fn walker<'f>(
        &self,
        faces: &Faces<'_>,
        vertices: &[Vec3],
        fan: &'f [(u32, u32)],
    ) -> Option<Walker<'f>> {
        let width = self.width();
        if !(width > 0.0 && width.is_finite()) {
            return None;
        }
        // The two faces that turn most from each other.
        let mut most = (1.0f32, fan[0].1, fan[0].1);
        for (k, &(_, s)) in fan.iter().enumerate() {
            for &(_, t) in &fan[k + 1..] {
                let cos = faces.turn([s, t]);
                if cos < most.0 {
                    most = (cos, s, t);
                }
            }
        }
        let (v, (cos, s, t)) = (fan[0].0, most);
        if !(CREASE_COS..FLAT_COS).contains(&cos) {
            return None;
        }
        let at = vertices[v as usize];
        // As far again as its longest edge, for the edges round it.
        let longest = (fan.iter())
            .flat_map(|&(_, f)| faces.triangles[f as usize])
            .map(|i| at.distance(vertices[i as usize]))
            .fold(0.0f32, f32::max);
        Some(Walker {
            vertex: v,
            at,
            reference: bisector(faces.normals[s as usize], faces.normals[t as usize]),
            rings: RINGS + ((longest.min(self.edge) / width).ceil() as usize).min(RINGS),
            fan,
        })
    }

    /// What the walk of `walker` measured, from the least cosine it gathered in each of
    /// its rings (`least`).
    fn around_of(&self, walker: &Walker<'_>, least: &[f32]) -> Around {
        let mut steepest = [0.0f32; 2 * RINGS];
        let mut most = 0.0f32;
        for (k, &cos) in least.iter().enumerate() {
            most = most.max(cos.min(1.0).acos());
            steepest[k] = most;
        }
        let near: [f32; RINGS] = std::array::from_fn(|k| steepest[k].tan());
        let lever = self.lever;
        Around {
            steepest,
            rings: least.len(),
            reference: walker.reference,
            dip: dip_of(near, self.width(), (lever, lever * lever)),
        }
    }

    /// The walk of the vertex of `fan` on its own ([`ClothSpan::walker`]), one face after
    /// another ([`Faces::walk_rings`]): what the lanes of a group's walk must gather.
    #[cfg(test)]
    fn around(
        &self,
        faces: &Faces<'_>,
        walk: &mut Walk,
        vertices: &[Vec3],
        fan: &[(u32, u32)],
    ) -> Option<(u32, Around)> {
        let walker = self.walker(faces, vertices, fan)?;
        let mut least = [1.0f32; 2 * RINGS];
        let (place, starts) = ((walker.at, walker.at), fan.iter().map(|&(_, f)| f));
        let least = &mut least[..walker.rings];
        faces.walk_rings(
            walk,
            starts,
            (place, walker.reference),
            (self.width(), least),
        );
        Some((walker.vertex, self.around_of(&walker, least)))
    }
}

/// Each ring's steepest turn (radians) of it and every ring nearer, from each ring's least
/// cosine.
fn steepest(least: [f32; RINGS]) -> [f32; RINGS] {
    let mut most = 0.0f32;
    least.map(|cos| {
        most = most.max(cos.min(1.0).acos());
        most
    })
}

/// A closed prism of `sides` narrow faces round the x axis, `radius` from it and 2 m long,
/// with flat ends (a rail: its only vertices are at its ends), as vertices and triangles:
/// a gentle mesh whose every face turns less than a crease from the next, for tests.
pub fn prism(sides: u32, radius: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
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
