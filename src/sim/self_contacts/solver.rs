//! The self-contact solver: finds the pairs, pushes them apart, and cuts motion that
//! could make a pair meet (see the module's notes).

use glam::Vec3;
use rustc_hash::FxHashMap;

use crate::cloth::{ClothModel, ClothState};
use crate::parallel::{Disjoint, Team};

use super::ccd::safe_fraction;
use super::error::ContactError;
use super::hash::BoxHash;
use super::primitives::{Pair, StoredPair, distance, push_apart};

/// Work done by the last resolve: for cost checks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SelfWork {
    /// Vertex–triangle and edge–edge pairs whose boxes over the substep overlap.
    pub candidates: u64,
    /// Pushes that kept a pair a thickness apart at the substep's end.
    pub contacts: u64,
    /// Entries in the spatial hash's table (at most [`CELLS_PER_TRIANGLE`](super::CELLS_PER_TRIANGLE) per triangle).
    pub binned: u64,
    /// Searches of the hash (0 when the pairs found before still held).
    pub searches: u64,
    /// Pairs whose motion was cut short because their sides could otherwise have met.
    pub impacts: u64,
    /// Pairs that prescribed motion (pins, handles) drove together, so no cut could keep
    /// them apart.
    pub forced: u64,
    /// [`SelfWork::forced`] added up since the solver was made.
    pub forced_total: u64,
}

/// The separation the continuous check keeps, as a share of the thickness (pairs that
/// start closer keep half of what they start at).
const KEEP: f64 = 0.1;

/// The pairs found are kept for later substeps (their boxes given room) only while no
/// particle moves more than this share of the thickness in a substep.
const REUSE_BELOW: f32 = 0.5;

/// The distance, as a share of the thickness, within which the continuous check needs
/// its pairs: twice what it keeps, for margin (pairs farther apart along the whole motion
/// cannot come within [`KEEP`]). The pushes need the whole thickness.
const CHECKED: f32 = 2.0 * KEEP as f32;

/// Gauss–Seidel sweeps of the pushes over the pairs.
const PUSH_SWEEPS: usize = 4;

/// Rounds of cuts by the safe fraction; after them, a pair that can still meet has its
/// free particles sent back to the substep's start.
const SCALED_ROUNDS: usize = 4;

/// Which vertices and edges each triangle owns: each vertex and each edge belongs to the
/// first triangle that has it, so a pair of triangles yields each vertex–triangle and
/// edge–edge pair of theirs once.
#[derive(Clone, Debug, Default)]
struct Owners {
    /// What it was built for: triangle count, particle count and a hash of the triangles.
    key: (usize, usize, u64),
    vertices: Vec<[u32; 3]>,
    edges: Vec<[[u32; 2]; 3]>,
}

const NONE: u32 = u32::MAX;

impl Owners {
    fn key(model: &ClothModel) -> (usize, usize, u64) {
        use std::hash::{Hash, Hasher};
        let mut h = rustc_hash::FxHasher::default();
        model.triangles.hash(&mut h);
        (model.triangles.len(), model.particle_count(), h.finish())
    }

    fn build(model: &ClothModel) -> Owners {
        let mut seen = vec![false; model.particle_count()];
        let mut edges: FxHashMap<[u32; 2], ()> = FxHashMap::default();
        let mut owners = Owners {
            key: Self::key(model),
            vertices: Vec::with_capacity(model.triangles.len()),
            edges: Vec::with_capacity(model.triangles.len()),
        };
        for t in &model.triangles {
            let mut v = [NONE; 3];
            let mut e = [[NONE; 2]; 3];
            for k in 0..3 {
                let i = t[k] as usize;
                if !seen[i] {
                    seen[i] = true;
                    v[k] = t[k];
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

/// Reusable buffers of self-contact: nothing is allocated per substep once warm.
#[derive(Clone, Debug, Default)]
pub struct SelfContacts {
    hash: BoxHash,
    owners: Owners,
    /// Each particle's box when the pairs were found: its motion grown by half the
    /// thickness and a margin.
    vertex_lo: Vec<Vec3>,
    vertex_hi: Vec<Vec3>,
    /// The substep's start and end in the frame that moves with the cloth, and how far
    /// that frame has moved.
    from: Vec<Vec3>,
    to: Vec<Vec3>,
    shift: Vec3,
    /// The cloth's mean motion in the last substep resolved.
    mean: Vec3,
    /// Each triangle's box: its corners' boxes together.
    lo: Vec<Vec3>,
    hi: Vec<Vec3>,
    /// The pairs found last.
    found: Found,
    /// Particles resting on a solid this substep (set by the stepper before
    /// [`SelfContacts::resolve`]): pushes move them only where nothing else can.
    pub held: Vec<bool>,
    /// Particles the cuts leave alone besides the pinned (those the solids moved, in
    /// [`SelfContacts::settle`]); empty: none.
    fixed: Vec<bool>,
    /// The thickness the pairs were found for (`None`: none found, or a failed search).
    found_for: Option<f32>,
    /// How much of its motion each particle keeps, and whether that changed last round.
    scale: Vec<f64>,
    cut: Vec<f64>,
    changed: Vec<bool>,
    pub work: SelfWork,
}

/// Where one piece of the search put its pairs: `members[member][start..end]`.
#[derive(Clone, Copy, Debug, Default)]
struct Segment {
    member: u32,
    start: u32,
    end: u32,
}

/// The pairs, as each member of the team found them, and where each piece of the search
/// put its own (`pieces` of them in use): read in the pieces' order, they are the same
/// however the pieces were shared out.
#[derive(Clone, Debug, Default)]
struct Found {
    members: Vec<Vec<StoredPair>>,
    segments: Vec<Segment>,
    pieces: usize,
}

impl Found {
    /// The pairs as stored, in order.
    fn stored(&self) -> impl Iterator<Item = &StoredPair> {
        (self.segments[..self.pieces])
            .iter()
            .flat_map(|s| &self.members[s.member as usize][s.start as usize..s.end as usize])
    }

    /// The pairs, expanded with the cloth's `triangles` and the owned `edges`.
    fn pairs<'a>(
        &'a self,
        triangles: &'a [[u32; 3]],
        owners: &'a Owners,
    ) -> impl Iterator<Item = Pair> + 'a {
        self.stored().map(|p| p.expand(triangles, &owners.edges))
    }
}

/// Triangles from which the search shares its work out between the team's members.
const PARALLEL_TRIANGLES: usize = 2048;

/// What a search for pairs reads.
struct Search<'a> {
    owners: &'a Owners,
    triangles: &'a [[u32; 3]],
    vertex_lo: &'a [Vec3],
    vertex_hi: &'a [Vec3],
    lo: &'a [Vec3],
    hi: &'a [Vec3],
    thickness: f32,
}

impl Search<'_> {
    /// Adds to `out` the vertex–triangle and edge–edge pairs that triangles `a` and `b`
    /// (whose boxes overlap) own and that could come within the thickness.
    fn pairs_of(&self, a: usize, b: usize, out: &mut Vec<StoredPair>) {
        let vbox = |v: u32| (self.vertex_lo[v as usize], self.vertex_hi[v as usize]);
        let ebox = |[a, b]: [u32; 2]| {
            let (a, b) = (a as usize, b as usize);
            (
                self.vertex_lo[a].min(self.vertex_lo[b]),
                self.vertex_hi[a].max(self.vertex_hi[b]),
            )
        };
        for (own, other) in [(a, b), (b, a)] {
            let tri = self.triangles[other];
            for &v in &self.owners.vertices[own] {
                if v != NONE && !tri.contains(&v) && meet(vbox(v), (self.lo[other], self.hi[other]))
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
    /// could come within the thickness.
    fn keep(&self, pair: Pair, stored: StoredPair, out: &mut Vec<StoredPair>) {
        let ids = pair.ids();
        // The smallest ball around each particle's box: in its box, a particle is at most
        // half the box's diagonal from the box's centre.
        let (lo, hi) = (
            ids.map(|i| self.vertex_lo[i]),
            ids.map(|i| self.vertex_hi[i]),
        );
        let x = std::array::from_fn(|j| (0.5 * (lo[j] + hi[j])).as_dvec3());
        let radius = |j: usize| 0.5 * f64::from((hi[j] - lo[j]).length());
        let most = |r: std::ops::Range<usize>| r.map(radius).fold(0.0f64, f64::max);
        let k = pair.first_side();
        if distance(&pair, x) - most(0..k) - most(k..4) < f64::from(self.thickness) {
            // Grown by half, not doubled: where a cloth lands fast the pairs run to
            // millions, and a doubled buffer can hold as much again unused.
            if out.len() == out.capacity() {
                out.reserve_exact((out.capacity() / 2).max(1024));
            }
            out.push(stored);
        }
    }
}

/// Whether boxes `a` and `b` overlap.
fn meet((alo, ahi): (Vec3, Vec3), (blo, bhi): (Vec3, Vec3)) -> bool {
    alo.cmple(bhi).all() && blo.cmple(ahi).all()
}

impl SelfContacts {
    /// Keeps the cloth off itself after a substep of `substep` seconds that moved it from
    /// `start` to `state`: pairs closer than `thickness` (m) are pushed apart on the side
    /// they started on, with Coulomb `friction`; then no pair's sides may meet anywhere along
    /// the substep's straight-line motion. Returns the pushes.
    ///
    /// # Errors
    /// [`ContactError`] for a state that has blown up (a non-finite position, or a triangle
    /// a million times wider than the cloth's scale); nothing is moved then.
    pub fn resolve(
        &mut self,
        [thickness, friction, substep]: [f32; 3],
        model: &ClothModel,
        start: &[Vec3],
        state: &mut ClothState,
    ) -> Result<usize, ContactError> {
        if thickness <= 0.0 || model.triangles.is_empty() {
            return Ok(0);
        }
        if let Some(particle) = state.pos.iter().position(|p| !p.is_finite()) {
            return Err(ContactError::NonFinite { particle });
        }
        if self.owners.key != Owners::key(model) {
            self.owners = Owners::build(model);
        }
        // Only the running total outlives a resolve.
        self.work = SelfWork {
            forced_total: self.work.forced_total,
            ..SelfWork::default()
        };
        // Pairs are found, and kept while they hold, in a frame that moves with the
        // cloth's mean motion (it changes no distance): a cloth falling as a whole moves
        // little in it.
        let n = start.len() as f64;
        let mean = (start.iter().zip(&state.pos))
            .fold(glam::DVec3::ZERO, |m, (s, p)| m + (*p - *s).as_dvec3())
            / n;
        let mean = mean.as_vec3();
        self.relative(start, &state.pos, self.shift, mean);
        if !self.holds(thickness, thickness) {
            self.find_pairs(model, thickness)?;
        }
        self.work.candidates = self.found.stored().count() as u64;
        self.work.binned = self.hash.len() as u64;
        let mut contacts = 0;
        for _ in 0..PUSH_SWEEPS {
            for pair in self.found.pairs(&model.triangles, &self.owners) {
                contacts += usize::from(push_apart(
                    &pair,
                    [thickness, friction],
                    model,
                    start,
                    state,
                    &self.held,
                ));
            }
        }
        self.work.contacts = contacts as u64;
        // The pushes may have taken a particle out of the box its pairs were found in; the
        // check needs only the pairs that can come within what it keeps.
        self.relative(start, &state.pos, self.shift, mean);
        if !self.holds(thickness, CHECKED * thickness) {
            self.find_pairs(model, thickness)?;
        }
        self.shift += mean;
        self.mean = mean;
        self.fixed.clear();
        self.keep_apart(model, start, state, thickness, substep);
        Ok(contacts)
    }

    /// Checks the substep's motion again after [`SelfContacts::resolve`] and a move of the
    /// solids (from `start`, the substep's, free of intersections, to `state`; `placed`:
    /// the positions before the solids moved them) along its whole length, cutting it where
    /// a pair could meet, as `resolve` does but without pushes; what the solids moved is cut
    /// only where nothing else can be. Returns the pairs cut.
    ///
    /// # Errors
    /// As [`SelfContacts::resolve`].
    pub fn settle(
        &mut self,
        thickness: f32,
        substep: f32,
        model: &ClothModel,
        [start, placed]: [&[Vec3]; 2],
        state: &mut ClothState,
    ) -> Result<usize, ContactError> {
        if thickness <= 0.0 || model.triangles.is_empty() {
            return Ok(0);
        }
        // The substep in the frame it was resolved in (whose shift already has its mean).
        self.relative(start, &state.pos, self.shift - self.mean, self.mean);
        if !self.holds(thickness, CHECKED * thickness) {
            self.find_pairs(model, thickness)?;
        }
        let impacts = self.work.impacts;
        // What the solids just moved stays where they put it: the cut falls on the rest.
        self.fixed.clear();
        (self.fixed).extend(placed.iter().zip(&state.pos).map(|(a, b)| a != b));
        self.keep_apart(model, start, state, thickness, substep);
        Ok((self.work.impacts - impacts) as usize)
    }

    /// Entries in the hash's table now: at most [`CELLS_PER_TRIANGLE`](super::CELLS_PER_TRIANGLE) per triangle,
    /// whatever the positions.
    pub fn table_len(&self) -> usize {
        self.hash.len()
    }

    /// Fills the substep's start and end in the moving frame: less `shift`, how far the
    /// frame had moved by the substep's start, and the end less the substep's `mean` motion
    /// too.
    fn relative(&mut self, start: &[Vec3], pos: &[Vec3], shift: Vec3, mean: Vec3) {
        self.from.clear();
        self.from.extend(start.iter().map(|&s| s - shift));
        self.to.clear();
        self.to.extend(pos.iter().map(|&p| p - shift - mean));
    }

    /// Whether the pairs found last hold every pair that can come within `within` along the
    /// motion from `from` to `to`: found for this thickness, and every particle's motion
    /// within its box less half of `within` (two boxes that far apart keep their particles
    /// `within` apart).
    fn holds(&self, thickness: f32, within: f32) -> bool {
        let g = Vec3::splat(0.5 * within);
        self.found_for == Some(thickness)
            && self.vertex_lo.len() == self.to.len()
            && (self.from.iter().zip(&self.to))
                .zip(self.vertex_lo.iter().zip(&self.vertex_hi))
                .all(|((s, p), (lo, hi))| {
                    (s.min(*p) - g).cmpge(*lo).all() && (s.max(*p) + g).cmple(*hi).all()
                })
    }

    /// The pairs whose boxes overlap: each particle's box holds its motion from `from` to
    /// `to` grown by half the thickness, or (where the cloth moves slowly) three quarters of
    /// it, so the pairs hold for the substeps after as long as the motion stays in it less
    /// half the thickness.
    fn find_pairs(&mut self, model: &ClothModel, thickness: f32) -> Result<(), ContactError> {
        self.found_for = None;
        self.vertex_lo.clear();
        self.vertex_hi.clear();
        // Room to reuse the pairs only where the cloth moves slowly in the moving frame; a
        // fast substep would leave its boxes at once, and the room would only add pairs.
        let fastest = (self.from.iter().zip(&self.to))
            .map(|(s, p)| s.distance_squared(*p))
            .fold(0.0f32, f32::max)
            .sqrt();
        let grow = if fastest < REUSE_BELOW * thickness {
            0.75 * thickness
        } else {
            0.5 * thickness
        };
        for (s, p) in self.from.iter().zip(&self.to) {
            self.vertex_lo.push(s.min(*p) - Vec3::splat(grow));
            self.vertex_hi.push(s.max(*p) + Vec3::splat(grow));
        }
        let (vlo, vhi) = (&self.vertex_lo, &self.vertex_hi);
        self.lo.clear();
        self.hi.clear();
        for t in &model.triangles {
            let [a, b, c] = t.map(|i| i as usize);
            self.lo.push(vlo[a].min(vlo[b]).min(vlo[c]));
            self.hi.push(vhi[a].max(vhi[b]).max(vhi[c]));
        }
        let longest = model.springs.rest[..model.mesh_edges.min(model.springs.len())]
            .iter()
            .fold(0.0f32, |m, &r| m.max(r));
        let cell = (2.0 * longest).max(2.0 * thickness).max(1e-6);
        self.hash.bin(&self.lo, &self.hi, cell)?;
        let pieces = self.hash.pieces();
        self.found.pieces = 0;
        let team = Team::current();
        (self.found.members).resize_with(team.members().max(1), Vec::new);
        for buffer in &mut self.found.members {
            buffer.clear();
        }
        (self.found.segments).resize(pieces, Segment::default());
        let search = Search {
            owners: &self.owners,
            triangles: &model.triangles,
            vertex_lo: &self.vertex_lo,
            vertex_hi: &self.vertex_hi,
            lo: &self.lo,
            hi: &self.hi,
            thickness,
        };
        let (found, segments) = (
            Disjoint::new(&mut self.found.members),
            Disjoint::new(&mut self.found.segments),
        );
        let hash = &self.hash;
        let work = |member: usize, piece: usize| {
            // SAFETY: a member takes only its own buffer, and each piece is run once and
            // writes only its own segment.
            let (out, segment) = unsafe {
                (
                    &mut found.part(member..member + 1)[0],
                    &mut segments.part(piece..piece + 1)[0],
                )
            };
            let start = out.len();
            hash.piece_pairs(piece, &self.lo, &self.hi, |a, b| {
                search.pairs_of(a as usize, b as usize, out);
            });
            *segment = Segment {
                member: member as u32,
                start: start as u32,
                end: out.len() as u32,
            };
        };
        if model.triangles.len() >= PARALLEL_TRIANGLES {
            team.run_large_pieces(pieces, &work);
        } else {
            (0..pieces).for_each(|piece| work(0, piece));
        }
        self.found.pieces = pieces;
        self.work.searches += 1;
        self.found_for = Some(thickness);
        Ok(())
    }

    /// Cuts the free particles' motion short until no pair's sides can meet along the
    /// substep (see the module's notes); cut particles move at their remaining motion's
    /// average velocity.
    fn keep_apart(
        &mut self,
        model: &ClothModel,
        start: &[Vec3],
        state: &mut ClothState,
        thickness: f32,
        substep: f32,
    ) {
        let n = state.pos.len();
        let keep = KEEP * f64::from(thickness);
        let fixed = &self.fixed;
        let pinned_free = |i: usize| model.inv_mass[i] > 0.0;
        let free = |i: usize| pinned_free(i) && !fixed.get(i).copied().unwrap_or(false);
        self.scale.clear();
        self.scale.resize(n, 1.0);
        self.changed.clear();
        self.changed.resize(n, true);
        for round in 0.. {
            self.cut.clone_from(&self.scale);
            let mut any = false;
            for pair in self.found.pairs(&model.triangles, &self.owners) {
                let ids = pair.ids();
                if !ids.iter().any(|&i| self.changed[i]) {
                    continue;
                }
                let from = ids.map(|i| start[i].as_dvec3());
                let moves =
                    ids.map(|i| self.scale[i] * (state.pos[i].as_dvec3() - start[i].as_dvec3()));
                let t = safe_fraction(&pair, from, moves, keep);
                if t >= 1.0 {
                    continue;
                }
                self.work.impacts += 1;
                // Particles a solid placed are cut only where nothing else in the pair can be:
                // the cloth's own guarantee comes first.
                let only_placed = !ids.iter().any(|&i| free(i) && self.scale[i] > 0.0);
                let movable = |i: usize| {
                    self.scale[i] > 0.0 && if only_placed { pinned_free(i) } else { free(i) }
                };
                let mut cut_any = false;
                for &i in &ids {
                    if movable(i) {
                        let to = if round < SCALED_ROUNDS {
                            self.scale[i] * t
                        } else {
                            0.0
                        };
                        if to < self.cut[i] {
                            self.cut[i] = to;
                        }
                        cut_any = true;
                    }
                }
                if cut_any {
                    any = true;
                } else {
                    self.work.forced += 1;
                    self.work.forced_total += 1;
                }
            }
            if !any {
                break;
            }
            for ((changed, cut), scale) in self.changed.iter_mut().zip(&self.cut).zip(&self.scale) {
                *changed = cut != scale;
            }
            std::mem::swap(&mut self.scale, &mut self.cut);
        }
        let moved = (self.scale.iter().zip(start)).zip(state.pos.iter_mut().zip(&mut state.vel));
        for ((&s, from), (pos, vel)) in moved {
            if s < 1.0 {
                let from = from.as_dvec3();
                let to = from + s * (pos.as_dvec3() - from);
                *pos = to.as_vec3();
                *vel = ((to - from) / f64::from(substep)).as_vec3();
            }
        }
    }
}
