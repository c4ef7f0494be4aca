//! What a search for pairs reads and keeps: which vertices and edges each triangle owns,
//! the boxes, and the test that keeps a vertex–triangle or edge–edge pair of two triangles
//! whose boxes overlap.

use glam::Vec3;
use rustc_hash::FxHashMap;

use super::ccd::closing_bound;
use super::found::Found;
use super::primitives::{Pair, StoredPair, distance};
use crate::cloth::ClothModel;

/// Which vertices and edges each triangle owns: each vertex and each edge belongs to the
/// first triangle that has it, so a pair of triangles yields each vertex–triangle and
/// edge–edge pair of theirs once.
#[derive(Clone, Debug, Default)]
pub(super) struct Owners {
    /// The model it serves, as told apart cheaply every substep: where its triangles lie
    /// in memory, how many there are, and how many particles.
    identity: (usize, usize, usize),
    /// What it was built for: triangle count, particle count and a hash of the triangles.
    key: (usize, usize, u64),
    /// The model's longest mesh edge at rest, m (the hash's base cell is twice it).
    pub(super) longest: f32,
    pub(super) vertices: Vec<[u32; 3]>,
    pub(super) edges: Vec<[[u32; 2]; 3]>,
    /// Each particle's owning triangle ([`NONE`] for a particle in none).
    pub(super) vertex_owner: Vec<u32>,
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
        let mut seen = vec![false; model.particle_count()];
        let mut edges: FxHashMap<[u32; 2], ()> = FxHashMap::default();
        let mut owners = Owners {
            identity: (0, 0, 0),
            key: Self::key(model),
            longest: (model.edge_rest_lengths().iter()).fold(0.0f32, |m, &r| m.max(r)),
            vertices: Vec::with_capacity(model.triangles.len()),
            edges: Vec::with_capacity(model.triangles.len()),
            vertex_owner: vec![NONE; model.particle_count()],
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
}

/// The boxes a search bins and reads.
#[derive(Clone, Debug, Default)]
pub(super) struct Boxes {
    /// Each particle's: its motion grown by half the thickness or more.
    pub(super) vertex_lo: Vec<Vec3>,
    pub(super) vertex_hi: Vec<Vec3>,
    /// Each triangle's: its corners' boxes together.
    pub(super) lo: Vec<Vec3>,
    pub(super) hi: Vec<Vec3>,
    /// Whether the pairs were also judged by each particle's motion, from `from` to `to`
    /// (in the moving frame): where the cloth moves fast, and the boxes have no room to
    /// reuse them in later substeps anyway.
    pub(super) swept: bool,
    pub(super) from: Vec<Vec3>,
    pub(super) to: Vec<Vec3>,
}

/// What a search for pairs reads.
pub(super) struct Search<'a> {
    pub(super) owners: &'a Owners,
    pub(super) triangles: &'a [[u32; 3]],
    pub(super) boxes: &'a Boxes,
    pub(super) thickness: f32,
}

impl Search<'_> {
    /// Adds to `out` the vertex–triangle and edge–edge pairs that triangles `a` and `b`
    /// (whose boxes overlap) own and that could come within the thickness.
    pub(super) fn pairs_of(&self, a: usize, b: usize, out: &mut Vec<StoredPair>) {
        let vbox = |v: u32| {
            (
                self.boxes.vertex_lo[v as usize],
                self.boxes.vertex_hi[v as usize],
            )
        };
        let ebox = |[a, b]: [u32; 2]| {
            let (a, b) = (a as usize, b as usize);
            (
                self.boxes.vertex_lo[a].min(self.boxes.vertex_lo[b]),
                self.boxes.vertex_hi[a].max(self.boxes.vertex_hi[b]),
            )
        };
        for (own, other) in [(a, b), (b, a)] {
            let tri = self.triangles[other];
            for &v in &self.owners.vertices[own] {
                if v != NONE
                    && !tri.contains(&v)
                    && meet(vbox(v), (self.boxes.lo[other], self.boxes.hi[other]))
                {
                    let stored = StoredPair::vertex_triangle(v, other as u32);
                    self.keep(Pair::vertex_triangle(v, tri), stored, out);
                }
            }
        }
        for (j, &e) in self.owners.edges[a].iter().enumerate() {
            for (k, &f) in self.owners.edges[b].iter().enumerate() {
                if e[0] != NONE
                    && f[0] != NONE
                    && !e.iter().any(|i| f.contains(i))
                    && meet(ebox(e), ebox(f))
                {
                    let stored = StoredPair::edge_edge((3 * a + j) as u32, (3 * b + k) as u32);
                    self.keep(Pair::edge_edge(e, f), stored, out);
                }
            }
        }
    }

    /// Keeps `pair` (as `stored`) if, with each particle anywhere in its box, its sides
    /// could come within the thickness, and (where the boxes are `swept`) if they could
    /// along the motion the boxes were made for.
    fn keep(&self, pair: Pair, stored: StoredPair, out: &mut Vec<StoredPair>) {
        let ids = pair.ids();
        // The smallest ball around each particle's box: in its box, a particle is at most
        // half the box's diagonal from the box's centre.
        let (lo, hi) = (
            ids.map(|i| self.boxes.vertex_lo[i]),
            ids.map(|i| self.boxes.vertex_hi[i]),
        );
        let x = std::array::from_fn(|j| (0.5 * (lo[j] + hi[j])).as_dvec3());
        let radius = |j: usize| 0.5 * f64::from((hi[j] - lo[j]).length());
        let most = |r: std::ops::Range<usize>| r.map(radius).fold(0.0f64, f64::max);
        let k = pair.first_side();
        let thickness = f64::from(self.thickness);
        if distance(&pair, x) - most(0..k) - most(k..4) < thickness
            && (!self.boxes.swept || self.swept_apart(&pair) < thickness)
        {
            // Grown by a quarter, not doubled: where a cloth lands fast the pairs run to
            // millions, and a doubled buffer can hold as much again unused (a large
            // buffer grows in place: the allocator remaps its pages).
            if out.len() == out.capacity() {
                out.reserve_exact((out.capacity() / 4).max(1024));
            }
            out.push(stored);
        }
    }

    /// A lower bound on how close the pair's sides come along the particles' straight
    /// motion the boxes were made for: its distance changes along the motion no faster
    /// than the sides' largest displacements relative to the pair's mean motion add up to
    /// (`L`), so it stays above both `d₀ − τL` and `d₁ − (1 − τ)L`, whose larger is least,
    /// `(d₀ + d₁ − L)/2`, where they cross.
    fn swept_apart(&self, pair: &Pair) -> f64 {
        let ids = pair.ids();
        let (from, to) = (&self.boxes.from, &self.boxes.to);
        let x0 = ids.map(|i| from[i].as_dvec3());
        let x1 = ids.map(|i| to[i].as_dvec3());
        let moves = std::array::from_fn(|j| x1[j] - x0[j]);
        0.5 * (distance(pair, x0) + distance(pair, x1) - closing_bound(pair, moves))
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
fn meet((alo, ahi): (Vec3, Vec3), (blo, bhi): (Vec3, Vec3)) -> bool {
    alo.cmple(bhi).all() && blo.cmple(ahi).all()
}
