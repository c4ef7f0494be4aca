//! What a search for pairs reads and keeps: which vertices and edges each triangle owns,
//! the boxes, and the test that keeps a vertex–triangle or edge–edge pair of two triangles
//! whose boxes overlap.

use glam::{DVec3, Vec3, Vec3A, Vec4};
use rustc_hash::FxHashMap;

use super::ccd::closing_bound;
use super::found::Found;
use super::gap::gap_at_both_ends;
use super::primitives::{Pair, StoredPair, distance};
use super::rings::Rings;
use crate::cloth::{ClothModel, Real, Vector};
use crate::mesh::{grouped, triangles_around};
use crate::parallel::{each_part, within};

/// Which vertices and edges each triangle owns: each vertex and each edge belongs to the
/// first triangle that has it, so a pair of triangles yields each vertex–triangle and
/// edge–edge pair of theirs once. And the pairs of the triangles that share a corner, which
/// every search meets.
#[derive(Clone, Debug, Default)]
pub(super) struct Owners {
    /// The model it serves, as told apart cheaply every substep: where its triangles lie
    /// in memory, how many there are, and how many particles.
    identity: (usize, usize, usize),
    /// What it was built for: triangle count, particle count and a hash of the triangles.
    key: (usize, usize, u64),
    /// The model's longest mesh edge at rest, m.
    pub(super) longest: f32,
    pub(super) vertices: Vec<[u32; 3]>,
    pub(super) edges: Vec<[[u32; 2]; 3]>,
    /// Each particle's owning triangle ([`NONE`] for a particle in none).
    pub(super) vertex_owner: Vec<u32>,
    /// The vertex–triangle and edge–edge pairs of every two triangles that share a corner,
    /// by the corner they were taken at (`corner_start`, as rows). Their boxes always
    /// overlap (both hold the corner's), so every search has them: they are tested from
    /// this list, and the tree's search passes such triangles by. On a grid they are four
    /// in five of the overlapping triangles a search meets.
    pub(super) neighbours: Vec<StoredPair>,
    corner_start: Vec<u32>,
    /// The corners each piece of a search's neighbours starts at (and the last's end).
    piece_start: Vec<u32>,
    /// Each particle's ring, for the certificates ([`super::certify`]).
    pub(super) rings: Rings,
}

pub(super) const NONE: u32 = u32::MAX;

impl Owners {
    /// Brings the owners up to `model`: built anew when its triangles differ from those
    /// they were built for (hashed only when the model is another in memory, not every
    /// substep: hashing 8 192 triangles took 18 µs, half a spring pass at 64²). Returns
    /// whether they were, so that pairs found for the old triangles are dropped. A solver
    /// serves one model: another of the same size rebuilt at the same address after the
    /// first was freed would not be told apart (a `Simulation` makes a new solver with
    /// each model).
    pub(super) fn update(&mut self, model: &ClothModel) -> bool {
        let identity = (
            model.triangles.as_ptr() as usize,
            model.triangles.len(),
            model.particle_count(),
        );
        if identity == self.identity {
            return false;
        }
        self.identity = identity;
        if Self::key(model) == self.key {
            return false;
        }
        *self = Self::build(model);
        self.identity = identity;
        true
    }

    fn key(model: &ClothModel) -> (usize, usize, u64) {
        use std::hash::{Hash, Hasher};
        let mut h = rustc_hash::FxHasher::default();
        model.triangles.hash(&mut h);
        (model.triangles.len(), model.particle_count(), h.finish())
    }

    pub(super) fn build(model: &ClothModel) -> Owners {
        let mut owners = Self::owned(model);
        owners.neighbour_pairs(&model.triangles, model.particle_count());
        owners.rings = Rings::build(model.particle_count(), &model.triangles);
        owners
    }

    /// The cloth's cell, m: twice its longest mesh edge at rest, or twice `thickness`
    /// where that is more (a scale against which a triangle's box tells a state that has
    /// blown up).
    pub(super) fn cell(&self, thickness: f32) -> f32 {
        (2.0 * self.longest).max(2.0 * thickness).max(1e-6)
    }

    /// The pairs taken at corner `c` (see [`Owners::neighbours`]).
    pub(super) fn corner_pairs(&self, c: usize) -> &[StoredPair] {
        &self.neighbours[self.corner_start[c] as usize..self.corner_start[c + 1] as usize]
    }

    /// Which vertices and edges each triangle owns, without the neighbours' pairs.
    fn owned(model: &ClothModel) -> Owners {
        let mut seen = vec![false; model.particle_count()];
        let mut edges: FxHashMap<[u32; 2], ()> = FxHashMap::default();
        let mut owners = Owners {
            identity: (0, 0, 0),
            key: Self::key(model),
            longest: (model.edge_rest_lengths().iter()).fold(0.0f32, |m, &r| m.max(r)),
            vertices: Vec::with_capacity(model.triangles.len()),
            edges: Vec::with_capacity(model.triangles.len()),
            vertex_owner: vec![NONE; model.particle_count()],
            neighbours: Vec::new(),
            corner_start: Vec::new(),
            piece_start: Vec::new(),
            rings: Rings::default(),
        };
        for (n, t) in model.triangles.iter().enumerate() {
            let mut v = [NONE; 3];
            let mut e = [[NONE; 2]; 3];
            for k in 0..3 {
                let i = t[k] as usize;
                if !seen[i] {
                    seen[i] = true;
                    v[k] = t[k];
                    owners.vertex_owner[i] = n as u32;
                }
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let edge = [a.min(b), a.max(b)];
                if edges.insert(edge, ()).is_none() {
                    e[k] = edge;
                }
            }
            owners.vertices.push(v);
            owners.edges.push(e);
        }
        owners
    }

    /// Fills [`Owners::neighbours`]: the pairs of every two triangles sharing a corner, each
    /// pair of triangles taken once (from the lower-numbered, at the first corner they
    /// share), by that corner; and the pieces a search cuts them into.
    fn neighbour_pairs(&mut self, triangles: &[[u32; 3]], particles: usize) {
        let (start, around) = triangles_around(particles, triangles);
        // Each pair of triangles sharing a corner, with the corner it is taken at.
        let each = |visit: &mut dyn FnMut(u32, StoredPair)| {
            for (a, ta) in triangles.iter().enumerate() {
                for (k, &corner) in ta.iter().enumerate() {
                    let (from, to) = (start[corner as usize], start[corner as usize + 1]);
                    for &b in &around[from as usize..to as usize] {
                        let b = b as usize;
                        if b > a && !ta[..k].iter().any(|i| triangles[b].contains(i)) {
                            self.each_pair(triangles, a, b, |_, stored| visit(corner, stored));
                        }
                    }
                }
            }
        };
        // Counted, then placed (a corner's in the order they are met): no list of pairs
        // and their corners beside the result (16 MB at 256²).
        (self.corner_start, self.neighbours) = grouped(particles, each);
        self.piece_start = vec![0];
        for c in 0..particles {
            let first = self.corner_start[*self.piece_start.last().unwrap_or(&0) as usize];
            if (self.corner_start[c + 1] - first) as usize >= NEIGHBOURS_PER_PIECE {
                self.piece_start.push(c as u32 + 1);
            }
        }
        if *self.piece_start.last().unwrap_or(&0) as usize != particles {
            self.piece_start.push(particles as u32);
        }
    }

    /// Calls `visit` with each vertex–triangle and edge–edge pair that triangles `a` and
    /// `b` own: a vertex of one against the other triangle, if not its corner; an edge of
    /// each, if they share no particle.
    pub(super) fn each_pair(
        &self,
        triangles: &[[u32; 3]],
        a: usize,
        b: usize,
        mut visit: impl FnMut(Pair, StoredPair),
    ) {
        for (own, other) in [(a, b), (b, a)] {
            let tri = triangles[other];
            for &v in &self.vertices[own] {
                if v != NONE && !tri.contains(&v) {
                    let stored = StoredPair::vertex_triangle(v, other as u32);
                    visit(Pair::vertex_triangle(v, tri), stored);
                }
            }
        }
        for (j, &e) in self.edges[a].iter().enumerate() {
            for (k, &f) in self.edges[b].iter().enumerate() {
                if e[0] != NONE && f[0] != NONE && !e.iter().any(|i| f.contains(i)) {
                    let stored = StoredPair::edge_edge((3 * a + j) as u32, (3 * b + k) as u32);
                    visit(Pair::edge_edge(e, f), stored);
                }
            }
        }
    }
}

/// Which of each of `model`'s triangles' corners (bits 0–2) and edges (bits 3–5, edge k
/// from corner k to the next) it owns, as the CPU's search deals them out: for a search that
/// runs elsewhere (the GPU's) and must keep each pair once, as this one does.
pub fn owned_parts(model: &ClothModel) -> Vec<u32> {
    let owners = Owners::owned(model);
    (owners.vertices.iter().zip(&owners.edges))
        .map(|(v, e)| {
            (0..3)
                .map(|k| (u32::from(v[k] != NONE) << k) | (u32::from(e[k][0] != NONE) << (3 + k)))
                .sum()
        })
        .collect()
}

/// Pairs of [`Owners::neighbours`] tested in one piece of a search (at least: a corner's
/// pairs are not split).
pub(super) const NEIGHBOURS_PER_PIECE: usize = 4096;

/// The boxes a search bins and reads.
#[derive(Clone, Debug, Default)]
pub(super) struct Boxes {
    /// Each particle's: its motion grown by half the thickness or more.
    pub(super) vertex_lo: Vec<Vec3>,
    pub(super) vertex_hi: Vec<Vec3>,
    /// Each triangle's: its corners' boxes together (kept only where the pairs are judged
    /// by the boxes alone; by the motion the tree's fit stands in for them).
    pub(super) lo: Vec<Vec3>,
    pub(super) hi: Vec<Vec3>,
    /// Whether the pairs were also judged by each particle's motion, from `from` to `to`
    /// (in the moving frame): where the cloth moves fast, and the boxes have no room to
    /// reuse them in later substeps anyway.
    pub(super) swept: bool,
    from: Vec<Vec3>,
    to: Vec<Vec3>,
    /// `from` and `to` again, in SSE lanes (`Vec3A`): the patches' and the tree's fits read
    /// each particle's motion many times a search, and a `Vec3` is three loads and a
    /// shuffle to get into lanes (both set only by [`Boxes::set_motion`] and
    /// [`Boxes::set_path`]).
    lanes: [Vec<Vec3A>; 2],
}

impl Boxes {
    /// Sets each particle's motion to run from `from` to `to`, carried on `len` times as
    /// far from its start.
    pub(super) fn set_motion(&mut self, from: &[Vec3], to: &[Vec3], len: u32) {
        let n = from.len().min(to.len());
        self.from.resize(n, Vec3::ZERO);
        self.to.resize(n, Vec3::ZERO);
        // Each member of the team sets the particles it moved.
        each_part([&mut self.from, &mut self.to], |range, [s_out, e_out]| {
            let (from, to) = (within(from, range.clone()), within(to, range));
            for (((s_out, e_out), &s), &e) in s_out.iter_mut().zip(e_out).zip(from).zip(to) {
                let e = if len > 1 { s + (e - s) * len as f32 } else { e };
                (*s_out, *e_out) = (s, e);
            }
        });
        let [starts, ends] = &mut self.lanes;
        starts.resize(n, Vec3A::ZERO);
        ends.resize(n, Vec3A::ZERO);
        let (from, to) = (&self.from, &self.to);
        each_part([starts, ends], |range, [starts, ends]| {
            let (from, to) = (within(from, range.clone()), within(to, range));
            for (((s_out, e_out), &s), &e) in starts.iter_mut().zip(ends).zip(from).zip(to) {
                (*s_out, *e_out) = (s.into(), e.into());
            }
        });
    }

    /// Sets particle `i`'s motion to run from `s` to `p`.
    pub(super) fn set_path(&mut self, i: usize, s: Vec3, p: Vec3) {
        (self.from[i], self.to[i]) = (s, p);
        (self.lanes[0][i], self.lanes[1][i]) = (s.into(), p.into());
    }

    /// Each particle's motion, from its start to its end.
    pub(super) fn paths(&self) -> [&[Vec3]; 2] {
        [&self.from, &self.to]
    }

    /// [`Boxes::paths`] in SSE lanes.
    pub(super) fn motion(&self) -> [&[Vec3A]; 2] {
        [&self.lanes[0], &self.lanes[1]]
    }
}

/// Points in SSE lanes, as the patches' and the tree's fits read a motion.
#[cfg(test)]
pub(super) fn in_lanes(x: &[Vec3]) -> Vec<Vec3A> {
    x.iter().map(|&p| p.into()).collect()
}

/// What a search for pairs reads.
pub(super) struct Search<'a> {
    pub(super) owners: &'a Owners,
    pub(super) triangles: &'a [[u32; 3]],
    pub(super) boxes: &'a Boxes,
    pub(super) thickness: f32,
    /// Which corners' pairs are tested: by the motion, those the certificates left open
    /// (see [`super::certify`]); by the boxes, those whose ring no covered patch holds,
    /// and those a refresh touched (every search sets one flag a corner).
    pub(super) open: &'a [bool],
}

impl Search<'_> {
    /// Adds to `out` the vertex–triangle and edge–edge pairs that triangles `a` and `b`
    /// (whose boxes overlap, and that share no corner: those are left to
    /// [`Search::neighbours`]) own and that could come within the thickness.
    pub(super) fn pairs_of(&self, a: usize, b: usize, out: &mut Vec<StoredPair>) {
        if self.boxes.swept && self.apart_across(a, b) {
            return;
        }
        (self.owners).each_pair(self.triangles, a, b, |pair, stored| {
            if self.sides_meet(&pair) {
                self.keep(pair, stored, out);
            }
        });
    }

    /// Whether triangles `a` and `b` stay a thickness apart along the motion the boxes were
    /// made for, told along the line between their centres and then across the edge of the
    /// lower-numbered that faces the other: two triangles whose extents along a line are a
    /// thickness apart, in the same direction, at the start and at the end of the motion
    /// are at least that far apart all along it ([`super::gap`]). Two triangles of a smooth patch that share
    /// no corner overlap in their boxes wherever the patch runs across the axes, but most
    /// lie apart along the line between their centres; where that line runs obliquely (on
    /// a grid, two triangles whose diagonals run side by side with a strip of two
    /// triangles between: 0.7 of the spacing apart across the diagonals, a quarter along
    /// that line), across the edge. Told in f32 lanes first, and in f64 where they leave it
    /// open, so that no rounding keeps apart what touches.
    fn apart_across(&self, a: usize, b: usize) -> bool {
        // The lower-numbered first, so that a pair is told alike whichever way it is met
        // (a whole walk and a refresh meet it either way; the line between the centres
        // tells it alike both ways, the facing edge is the first's).
        let (a, b) = (a.min(b), a.max(b));
        self.apart_in_lanes(a, b) || self.apart_in_f64(a, b)
    }

    /// [`Search::apart_across`] in f64 (`a` the lower-numbered): what the lanes leave,
    /// one pair in thirty where `crumple` lands.
    #[inline(never)]
    fn apart_in_f64(&self, a: usize, b: usize) -> bool {
        let (from, to) = (&self.boxes.from, &self.boxes.to);
        let ends = |t: [u32; 3]| {
            let s = t.map(|i| from[i as usize].as_dvec3());
            let e = t.map(|i| to[i as usize].as_dvec3());
            (s, e)
        };
        let ((sa, ea), (sb, eb)) = (ends(self.triangles[a]), ends(self.triangles[b]));
        let sum = |x: [DVec3; 3]| x[0] + x[1] + x[2];
        let thickness = f64::from(self.thickness);
        let apart_along = |axis: DVec3| {
            let length = axis.length();
            if length == 0.0 {
                return false;
            }
            let span = |x: [DVec3; 3]| {
                (0..3).fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], k| {
                    let p = axis.dot(x[k]);
                    [lo.min(p), hi.max(p)]
                })
            };
            gap_at_both_ends([span(sa), span(sb)], [span(ea), span(eb)]) >= thickness * length
        };
        let across = (sum(sb) + sum(eb) - sum(sa) - sum(ea)) / 6.0;
        if apart_along(across) {
            return true;
        }
        // The edge of `a` (in its shape halfway along the motion) whose outward normal in
        // `a`'s plane points most nearly at `b`'s centre.
        let middle: [DVec3; 3] = std::array::from_fn(|k| 0.5 * (sa[k] + ea[k]));
        apart_along(facing_edge(middle, across))
    }

    /// [`Search::apart_across`] told first in f32, the four ends of the two triangles
    /// (each one's start and end) in SSE lanes, with room for the rounding: the points
    /// are taken from one of `a`'s corners (their differences rounded by at most a unit in
    /// the last place of their size), and a gap must clear the thickness by a
    /// hundred-thousandth of it and of the points' farthest coordinate, some twenty times
    /// what the projections' and the length's rounding could take. Where it says apart,
    /// the two are apart, and the f64 test along its own lines would say so too (they
    /// differ from these by rounding, far inside the room), so the same pairs are kept;
    /// only where two edges face `b` almost alike could each test pick another, and
    /// either edge's gap is a proof.
    #[inline(always)]
    fn apart_in_lanes(&self, a: usize, b: usize) -> bool {
        const ROOM: f32 = 1e-5;
        let [from, to] = self.boxes.motion();
        let (ta, tb) = (self.triangles[a], self.triangles[b]);
        let origin = from[ta[0] as usize];
        // Corner k of `a`'s start, `b`'s start, `a`'s end and `b`'s end, less the origin;
        // and the same in rows: each coordinate of the four in the lanes of one vector.
        let corner = |k: usize| {
            let (i, j) = (ta[k] as usize, tb[k] as usize);
            [from[i], from[j], to[i], to[j]].map(|p| p - origin)
        };
        let corners = [corner(0), corner(1), corner(2)];
        let rows = corners.map(|c| {
            let row = |d: usize| Vec4::new(c[0][d], c[1][d], c[2][d], c[3][d]);
            [row(0), row(1), row(2)]
        });
        let far = (rows.iter().flatten())
            .fold(Vec4::ZERO, |m, r| m.max(r.abs()))
            .max_element();
        let slack = self.thickness * (1.0 + ROOM) + 2.0 * ROOM * far;
        let apart_along = |axis: Vec3A| {
            // A NaN in any corner makes the line between the centres NaN, and its length,
            // and leaves no edge facing along it: nothing is told apart then.
            let length = axis.length();
            if length == 0.0 {
                return false;
            }
            // Each corner's place along the axis at the four ends, and each end's span
            // (lanes: `a`'s start, `b`'s, `a`'s end, `b`'s).
            let along = rows.map(|[x, y, z]| axis.x * x + axis.y * y + axis.z * z);
            let lo = along[0].min(along[1]).min(along[2]);
            let hi = along[0].max(along[1]).max(along[2]);
            let span = |k: usize| [lo[k], hi[k]];
            gap_at_both_ends([span(0), span(1)], [span(2), span(3)]) >= slack * length
        };
        let sum = |s: usize| corners[0][s] + corners[1][s] + corners[2][s];
        let across = (sum(1) + sum(3) - sum(0) - sum(2)) / 6.0;
        if apart_along(across) {
            return true;
        }
        // The edge of `a` (halfway along the motion) whose outward normal in `a`'s plane
        // points most nearly at `b`'s centre.
        let middle = corners.map(|c| 0.5 * (c[0] + c[2]));
        apart_along(facing_edge(middle, across))
    }

    /// Adds to `out` the pairs of piece `piece` of [`Owners::neighbours`] that could come
    /// within the thickness; with `dirty` (triangles, and the corners whose pairs lie on
    /// them), only those of a triangle it flags. The pairs of a corner the certificates
    /// closed are passed by.
    pub(super) fn neighbours(
        &self,
        piece: usize,
        dirty: Option<[&[bool]; 2]>,
        out: &mut Vec<StoredPair>,
    ) -> u64 {
        let starts = &self.owners.piece_start;
        let owner = &self.owners.vertex_owner;
        let mut tested = 0;
        for c in starts[piece] as usize..starts[piece + 1] as usize {
            if !self.open[c] {
                continue;
            }
            if dirty.is_some_and(|[_, corners]| !corners[c]) {
                continue;
            }
            let dirty = dirty.map(|[triangles, _]| triangles);
            for &stored in self.owners.corner_pairs(c) {
                if dirty.is_some_and(|d| !stored.triangles(owner).iter().any(|&t| d[t as usize])) {
                    continue;
                }
                tested += 1;
                let pair = stored.expand(self.triangles, &self.owners.edges);
                if self.sides_meet(&pair) {
                    self.keep(pair, stored, out);
                }
            }
        }
        tested
    }

    /// Pieces [`Search::neighbours`] is cut into.
    pub(super) fn neighbour_pieces(&self) -> usize {
        self.owners.piece_start.len().saturating_sub(1)
    }

    /// Whether the boxes of the pair's two sides (each its particles' boxes together)
    /// overlap.
    #[inline]
    pub(super) fn sides_meet(&self, pair: &Pair) -> bool {
        let [i, j, k, l] = pair.ids();
        let (lo, hi) = (&self.boxes.vertex_lo, &self.boxes.vertex_hi);
        let (blo, bhi) = (lo[k].min(lo[l]), hi[k].max(hi[l]));
        let first = if pair.edges() {
            (lo[i].min(lo[j]), hi[i].max(hi[j]))
        } else {
            (lo[i], hi[i])
        };
        let second = if pair.edges() {
            (blo, bhi)
        } else {
            (blo.min(lo[j]), bhi.max(hi[j]))
        };
        meet(first, second)
    }

    /// Keeps `pair` (as `stored`) if its sides could come within the thickness: where the
    /// boxes are `swept`, along the motion they were made for (the pairs then hold for
    /// that motion alone, so the boxes need not be asked); otherwise with each particle
    /// anywhere in its box.
    pub(super) fn keep(&self, pair: Pair, stored: StoredPair, out: &mut Vec<StoredPair>) {
        let near = if self.boxes.swept {
            self.swept_near(&pair)
        } else {
            self.boxed_near(&pair)
        };
        if near {
            // Grown by a quarter, not doubled: where a cloth lands fast the pairs run to
            // millions, and a doubled buffer can hold as much again unused (a large
            // buffer grows in place: the allocator remaps its pages).
            if out.len() == out.capacity() {
                out.reserve_exact((out.capacity() / 4).max(1024));
            }
            out.push(stored);
        }
    }

    /// Whether the pair's sides could come within the thickness with each particle anywhere
    /// in its box less half the thickness each way (judged by the boxes, the pairs hold
    /// while each particle's motion lies there): there, a particle is at most half that
    /// box's diagonal from its centre (the smallest ball around the box). Where two of
    /// the sides' particles' centres are that near already, the sides are (a side holds
    /// its particles): stacked cloths keep most of their pairs so, without their distance.
    fn boxed_near(&self, pair: &Pair) -> bool {
        let ids = pair.ids();
        let (lo, hi) = (
            ids.map(|i| self.boxes.vertex_lo[i]),
            ids.map(|i| self.boxes.vertex_hi[i]),
        );
        let x = std::array::from_fn(|j| (0.5 * (lo[j] + hi[j])).as_dvec3());
        let t = self.thickness;
        let radius = |j: usize| 0.5 * f64::from((hi[j] - lo[j] - t).max(Vec3::ZERO).length());
        let most = |r: std::ops::Range<usize>| r.map(radius).fold(0.0f64, f64::max);
        let k = pair.first_side();
        let reach = f64::from(t) + most(0..k) + most(k..4);
        let nearest = (0..k)
            .flat_map(|i| (k..4).map(move |j| (i, j)))
            .map(|(i, j)| x[i].distance_squared(x[j]))
            .fold(f64::INFINITY, f64::min);
        nearest < reach * reach || distance(pair, x) < reach
    }

    /// Whether the pair's sides could come within the thickness along the particles'
    /// straight motion the boxes were made for. First the sides' boxes: where along an
    /// axis, in the same direction, the sides' boxes at the start lie a thickness apart and
    /// so do those at the end, the sides keep that far apart all along ([`super::gap`]);
    /// most pairs that move together are told apart there.
    /// Then the same along the line between the sides' middles (two sides a cell apart on
    /// a patch that runs across the axes are told apart there). Then the distances at the
    /// start and the end (`d₀`, `d₁`): either within the thickness keeps the pair (four in
    /// five of those `layers` keeps are so); otherwise the distance changes along the
    /// motion no faster than the sides' largest displacements relative to the pair's mean
    /// motion add up to (`L`), so it stays above both `d₀ − τL` and `d₁ − (1 − τ)L`, whose
    /// larger is least, `(d₀ + d₁ − L)/2`, where they cross.
    fn swept_near(&self, pair: &Pair) -> bool {
        let ids = pair.ids();
        let (from, to) = (&self.boxes.from, &self.boxes.to);
        let x0 = ids.map(|i| from[i].as_dvec3());
        let x1 = ids.map(|i| to[i].as_dvec3());
        let moves: [DVec3; 4] = std::array::from_fn(|j| x1[j] - x0[j]);
        let k = pair.first_side();
        let sides = [0..k, k..4];
        let thickness = f64::from(self.thickness);
        // The two sides' boxes with the particles at `x`.
        let boxes = |x: &[DVec3; 4]| {
            let side = |r: std::ops::Range<usize>| {
                r.fold([DVec3::INFINITY, DVec3::NEG_INFINITY], |[lo, hi], j| {
                    [lo.min(x[j]), hi.max(x[j])]
                })
            };
            [side(0..k), side(k..4)]
        };
        if gap_at_both_ends(boxes(&x0), boxes(&x1)).max_element() >= thickness {
            return false;
        }
        // Then along the line between the sides' middles: where a smooth patch runs
        // across the axes, two sides a cell apart are apart along it.
        let middle = |r: std::ops::Range<usize>| {
            let n = r.len() as f64;
            r.map(|j| x0[j] + x1[j]).sum::<DVec3>() / (2.0 * n)
        };
        let axis = middle(sides[1].clone()) - middle(sides[0].clone());
        let span = |x: &[DVec3; 4], r: std::ops::Range<usize>| {
            r.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), j| {
                let p = axis.dot(x[j]);
                (lo.min(p), hi.max(p))
            })
        };
        let ahead = |x: &[DVec3; 4]| span(x, sides[1].clone()).0 - span(x, sides[0].clone()).1;
        let length = axis.length();
        if ahead(&x0).min(ahead(&x1)) >= thickness * length && length > 0.0 {
            return false;
        }
        let first = distance(pair, x0);
        if first < thickness {
            return true;
        }
        let last = distance(pair, x1);
        last < thickness || 0.5 * (first + last - closing_bound(pair, moves)) < thickness
    }
}

/// The pairs `found`, expanded with the cloth's `triangles` and the owned edges.
pub(super) fn pairs<'a>(
    found: &'a Found,
    triangles: &'a [[u32; 3]],
    owners: &'a Owners,
) -> impl Iterator<Item = Pair> + 'a {
    found.stored().map(|p| p.expand(triangles, &owners.edges))
}

/// Whether boxes `a` and `b` overlap.
pub(super) fn meet((alo, ahi): (Vec3, Vec3), (blo, bhi): (Vec3, Vec3)) -> bool {
    alo.cmple(bhi).all() && blo.cmple(ahi).all()
}

/// The outward normal, in the plane of the triangle with corners `middle`, of its edge
/// that faces most nearly along `across` (zero where none faces along it at all).
#[inline(always)]
fn facing_edge<R: Real, V: Vector<R>>(middle: [V; 3], across: V) -> V {
    let normal = (middle[1] - middle[0]).cross(middle[2] - middle[0]);
    let (mut facing, mut best) = (V::ZERO, R::ZERO);
    for k in 0..3 {
        let out = (middle[(k + 1) % 3] - middle[k]).cross(normal);
        let length = out.length();
        let towards = if length > R::ZERO {
            out.dot(across) / length
        } else {
            R::ZERO
        };
        if towards > best {
            (facing, best) = (out, towards);
        }
    }
    facing
}

#[cfg(test)]
mod tests;
